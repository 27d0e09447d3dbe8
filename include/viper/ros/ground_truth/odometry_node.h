// odometry: the camera's pose from the view matrix as tf (map -> camera body -> optical frame),
// nav_msgs/Odometry with velocities, and nav_msgs/Path. Topics and parameters:
// docs/ground_truth_nodes.md.
#pragma once

#include "viper/ros/ground_truth/odometry_step.h"
#include "viper/ros/ground_truth/step_log.h"
#include "viper/ros/measurement/cpu_meter.h"

#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <viper/DrawList.h>

#include <memory>
#include <optional>

namespace viper {

/// The odometry node's class, shared by the node and the nodelet.
class Odometry {
 public:
  Odometry(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads parameters, subscribes and advertises; false after ROS_FATAL on impossible settings.
  bool start();

 private:
  void onDraws(const DrawList::ConstPtr& draws);

  ros::NodeHandle nh_, private_nh_;
  StepLog log_;
  std::unique_ptr<OdometryMessageStep> step_;
  bool publish_tf_ = true;
  ros::Subscriber draws_sub_;
  ros::Publisher odom_pub_, path_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_tf_;
  CpuMeter cpu_{"odometry", nh_};  // per-frame CPU (cpu_meter.h)
};

}  // namespace viper
