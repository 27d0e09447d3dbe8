// capture_bridge as a nodelet: the same CaptureBridge, sharing images zero-copy inside a manager.
#include "viper/ros/bridge/capture_bridge.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class CaptureBridgeNodelet : public ShellNodelet<CaptureBridge> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::CaptureBridgeNodelet, nodelet::Nodelet)
