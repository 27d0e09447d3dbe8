// The inputs of an export into VIPER's layout, by role (color, semantic, flow, boxes, ...): their
// default topics and message types, and how one message of a role is handed to the ViperExporter.
// Shared by the export_viper command (bags) and the viper_exporter node (live topics).
#pragma once

#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/dataset/viper_exporter.h"

#include <ros/time.h>

#include <functional>
#include <string>
#include <vector>

namespace viper {

/// One kind of input: its name, topic ("" = off) and message type.
struct ExportRole {
  std::string name, topic, datatype;
};

/// Every role with the topics replay.launch publishes: color, semantic, instance_ids,
/// instances_viper, flow, flowbw, boxes (boxes_optical), objects, draws, odom, camera_info.
std::vector<ExportRole> defaultExportRoles();
/// The role called `name`, or null.
ExportRole* findExportRole(std::vector<ExportRole>& roles, const std::string& name);
/// The role called `name`; throws std::logic_error if there is none.
const ExportRole& exportRole(const std::vector<ExportRole>& roles, const std::string& name);

/// Hands one message to the exporter as part of frame `frame`; returns what is wrong, or "".
using ExportDispatch = std::function<std::string(ViperExporter&, uint64_t frame)>;

/// The dispatch of a message of role `role` (its type is the role's datatype).
ExportDispatch exportDispatch(const std::string& role, const sensor_msgs::ImageConstPtr& m);
ExportDispatch exportDispatch(const std::string& role, const Box3DArray::ConstPtr& m);
ExportDispatch exportDispatch(const std::string& role, const ObjectArray::ConstPtr& m);
ExportDispatch exportDispatch(const std::string& role, const DrawList::ConstPtr& m);
ExportDispatch exportDispatch(const std::string& role, const nav_msgs::Odometry::ConstPtr& m);
ExportDispatch exportDispatch(const std::string& role, const sensor_msgs::CameraInfo::ConstPtr& m);

/// A bag message of `datatype` for role `role`: its header stamp and its dispatch. False if the
/// type is not one of the roles' types (or not the message's: another md5sum); throws ros::Exception
/// for a message it cannot read.
bool exportDispatchFromBag(const std::string& role, const std::string& datatype, const BagReadMessage& m,
                           ros::Time& stamp, ExportDispatch& dispatch);

/// A stamp as seconds.nanoseconds (every digit: stamps in messages are compared exactly).
std::string stampText(const ros::Time& t);

/// The exporter's camera source of a --camera / ~camera word: draws, odom, none.
CameraSource cameraSourceOf(const std::string& word);

/// What is wrong with export settings ("" if nothing), in the words of the command's options:
/// image format png|jpg, JPEG quality 0..100, PNG and deflate levels 0..9, palette viper|gray,
/// camera auto|draws|odom|none, 0 < near < far.
std::string exportOptionsProblem(const ViperExportOptions& options, const std::string& palette,
                                 const std::string& camera);

/// The class colors of a class table (CSV) as the cls palette. Throws what ClassTable::load throws.
dataset::ClassPalette classPalette(const std::string& class_table_csv);

}  // namespace viper
