// The converter between ground-truth core types (objects, boxes, poses, images) and ROS messages.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ros/bridge/capture_conversions.h"  // imageMsg, imageMsgPtr

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/Box3D.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>

#include <string>

namespace viper {

geometry_msgs::Pose toPoseMsg(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation);
geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose);
/// A tf transform: `t` is the pose of `child` in `parent` (parent_from_child).
geometry_msgs::TransformStamped toTransformMsg(const Eigen::Isometry3d& t, const ros::Time& stamp,
                                               const std::string& parent, const std::string& child);
Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& msg);

/// Name of a class id in `classes`, or "class_<id>" for ids outside the table.
std::string className(const ClassTable& classes, int class_id);

/// The objects of one frame. `world_pose` is the world matrix's translation and the rotation of its
/// polar decomposition; the 2D box is empty for objects without visible pixels.
ObjectArray toObjectArrayMsg(const std::vector<TrackedObject>& objects, const ClassTable& classes,
                             const std_msgs::Header& header);

/// An oriented box with its id, class and linear velocity (m/s, same frame as the box).
Box3D toBox3DMsg(const OrientedBox& box, int32_t id, uint8_t class_id, const ClassTable& classes,
                 const Eigen::Vector3d& velocity_mps);
/// Back to the core box (id, class and velocity are left to the caller).
OrientedBox fromBox3DMsg(const Box3D& msg);

/// rviz markers of `boxes`: a translucent cube per box colored by class (namespace "boxes") and a
/// text label "class id" above it (namespace "labels"), preceded by a DELETEALL so boxes of earlier
/// frames disappear.
visualization_msgs::MarkerArray boxMarkers(const Box3DArray& boxes, const ClassTable& classes);

/// Fills `frame`'s size, number, time, draws and draw ids from a draw list and a draw id image
/// (32SC1). Returns an empty string, or what is wrong (encoding, size, stamps that differ).
std::string frameFromDrawMsgs(const DrawList& draws, const sensor_msgs::Image& draw_ids, CaptureFrame& frame);

}  // namespace viper
