// The ground-truth nodes as nodelets: the same classes as the nodes, so a whole replay can run
// zero-copy in one nodelet manager.
#include "viper/ros/ground_truth/boxes.h"
#include "viper/ros/ground_truth/instances.h"
#include "viper/ros/ground_truth/odometry.h"

#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {

class InstancesNodelet : public ShellNodelet<Instances> {};
class BoxesNodelet : public ShellNodelet<Boxes> {};
class OdometryNodelet : public ShellNodelet<Odometry> {};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::InstancesNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::BoxesNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(viper::OdometryNodelet, nodelet::Nodelet)
