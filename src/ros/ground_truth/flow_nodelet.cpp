// The flow node as a nodelet, so it runs zero-copy next to capture_bridge and instances.
#include "viper/ros/ground_truth/flow_node.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class FlowNodelet : public ShellNodelet<Flow> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::FlowNodelet, nodelet::Nodelet)
