// Objects and boxes: core types <-> viper/ObjectArray, viper/Box3D, and the rviz markers of boxes.
// Part of the converter between messages and core types (include/viper/ros/conversions/;
// docs/design.md).
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instance_pipeline.h"

#include <std_msgs/Header.h>
#include <viper/Box3D.h>
#include <viper/Box3DArray.h>
#include <viper/ObjectArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace viper {

/// Name of a class id in `classes`, or "class_<id>" for ids outside the table.
std::string className(const ClassTable& classes, int class_id);

/// The objects of one frame. `world_pose` is the world matrix's translation and the rotation of its
/// polar decomposition; the 2D box is empty for objects without visible pixels.
ObjectArray toObjectArrayMsg(const std::vector<TrackedObject>& objects, const ClassTable& classes,
                             const std_msgs::Header& header);
/// Back to the objects: track id, class (is_thing = a track id above 0), draws, pixel count, 2D
/// box and the world matrix of `world_pose` (a rigid transform: the message keeps no scale).
/// Box corners beyond INT_MAX (offset + size of the unsigned message box) are cut at INT_MAX.
/// Resource keys and 3D boxes are not in the message and stay empty.
std::vector<TrackedObject> fromObjectArrayMsg(const ObjectArray& msg);

/// An oriented box with its id, class and linear velocity (m/s, same frame as the box).
Box3D toBox3DMsg(const OrientedBox& box, int32_t id, uint8_t class_id, const ClassTable& classes,
                 const Eigen::Vector3d& velocity_mps);
/// Back to the core box (id, class and velocity are left to the caller).
OrientedBox fromBox3DMsg(const Box3D& msg);

/// rviz markers of `boxes`: a translucent cube per box colored by class (namespace "boxes") and a
/// text label "class id" above it (namespace "labels"), preceded by a DELETEALL so boxes of earlier
/// frames disappear.
visualization_msgs::MarkerArray boxMarkers(const Box3DArray& boxes, const ClassTable& classes);

}  // namespace viper
