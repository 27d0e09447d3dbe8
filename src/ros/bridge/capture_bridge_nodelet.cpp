// capture_bridge as a nodelet: the same CaptureBridge, sharing images zero-copy inside a manager.
#include "viper/ros/bridge/capture_bridge.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

/// Nodelet shell around CaptureBridge.
class CaptureBridgeNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    bridge_ = std::make_unique<CaptureBridge>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!bridge_->start(/*is_node=*/false)) {
      NODELET_FATAL("capture_bridge nodelet '%s' not started (see the message above)", getName().c_str());
    }
  }

  std::unique_ptr<CaptureBridge> bridge_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::CaptureBridgeNodelet, nodelet::Nodelet)
