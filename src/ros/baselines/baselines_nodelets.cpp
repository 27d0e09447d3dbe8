// The baseline nodes as nodelets, to run zero-copy in replay.launch's manager.
#include "viper/ros/baselines/flow_baseline.h"
#include "viper/ros/baselines/segmentation_baseline.h"
#include "viper/ros/baselines/vo_baseline.h"

#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {

class FlowBaselineNodelet : public ShellNodelet<FlowBaseline> {};
class VoBaselineNodelet : public ShellNodelet<VoBaseline> {};
class SegmentationBaselineNodelet : public ShellNodelet<SegmentationBaseline> {};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::FlowBaselineNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::VoBaselineNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::SegmentationBaselineNodelet, nodelet::Nodelet)
