// The evaluate node as a nodelet, so it scores the ground-truth nodelets' images zero-copy in the
// same manager. The report is written when the nodelet is unloaded (manager shutdown).
#include "viper/ros/evaluation/evaluate.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

class EvaluateNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<Evaluate>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!node_->start()) NODELET_FATAL("nodelet '%s' not started (see the message above)", getName().c_str());
  }
  std::unique_ptr<Evaluate> node_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::EvaluateNodelet, nodelet::Nodelet)
