// The live exporter as a nodelet: the same LiveExporter, reading the ground truth zero-copy inside a
// manager.
#include "viper/ros/dataset/live_exporter.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class LiveExporterNodelet : public ShellNodelet<LiveExporter> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::LiveExporterNodelet, nodelet::Nodelet)
