// The flow node as a nodelet, so it runs zero-copy next to capture_bridge and instances.
#include "viper/ros/ground_truth/flow.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

class FlowNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<Flow>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!node_->start()) NODELET_FATAL("nodelet '%s' not started (see the message above)", getName().c_str());
  }
  std::unique_ptr<Flow> node_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::FlowNodelet, nodelet::Nodelet)
