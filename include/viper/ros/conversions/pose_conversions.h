// Poses and transforms: Eigen <-> geometry_msgs / nav_msgs. Part of the converter between messages
// and core types (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>

#include <Eigen/Geometry>

#include <string>

namespace viper {

/// A pose message of a position and an orientation.
geometry_msgs::Pose toPoseMsg(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation);
/// A pose message of a rigid transform (its rotation as a unit quaternion).
geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose);
/// The rigid transform of a pose message; the quaternion is normalised (see checkedPoseFromMsg to
/// refuse a bad one instead).
Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& msg);
/// The same, refusing what is not a pose: returns "" and sets `pose`, or says what is wrong
/// (non-finite values, a quaternion whose norm is off 1 by more than 1e-3) and leaves it.
std::string checkedPoseFromMsg(const geometry_msgs::Pose& msg, Eigen::Isometry3d& pose);
/// The pose of an odometry message (pose.pose: child frame in the parent frame), checked as
/// checkedPoseFromMsg.
std::string poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d& pose);

/// A transform message of a rigid transform.
geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& t);
/// The rigid transform of a transform message (quaternion normalised).
Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& msg);
/// A tf transform: `t` is the pose of `child` in `parent` (parent_from_child).
geometry_msgs::TransformStamped toTransformMsg(const Eigen::Isometry3d& t, const ros::Time& stamp,
                                               const std::string& parent, const std::string& child);

}  // namespace viper
