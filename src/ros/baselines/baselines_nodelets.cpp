// The baseline nodes as nodelets, to run zero-copy in replay.launch's manager.
#include "viper/ros/baselines/flow_baseline.h"
#include "viper/ros/baselines/vo_baseline.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

/// Nodelet shell around a node class T with T(nh, private_nh) and bool start().
template <typename T>
class BaselineNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<T>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!node_->start()) NODELET_FATAL("nodelet '%s' not started (see the message above)", getName().c_str());
  }
  std::unique_ptr<T> node_;
};

class FlowBaselineNodelet : public BaselineNodelet<FlowBaseline> {};
class VoBaselineNodelet : public BaselineNodelet<VoBaseline> {};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::FlowBaselineNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::VoBaselineNodelet, nodelet::Nodelet)
