// The viper_exporter node as a nodelet: the same ViperExporterNode, reading the ground truth
// zero-copy inside a manager.
#include "viper/ros/dataset/viper_exporter_node.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class ViperExporterNodelet : public ShellNodelet<ViperExporterNode> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::ViperExporterNodelet, nodelet::Nodelet)
