#include "viper/ros/dataset/export_roles.h"

#include "viper/ground_truth/class_table.h"

#include <cstdio>
#include <stdexcept>

namespace viper {

std::vector<ExportRole> defaultExportRoles() {
  return {{"color", "/capture/color/image_raw", "sensor_msgs/Image"},
          {"semantic", "/ground_truth/semantic", "sensor_msgs/Image"},
          {"instance_ids", "/ground_truth/instance_ids", "sensor_msgs/Image"},
          {"instances_viper", "/ground_truth/instances_viper", "sensor_msgs/Image"},
          {"flow", "/ground_truth/flow/forward", "sensor_msgs/Image"},
          {"flowbw", "/ground_truth/flow/backward", "sensor_msgs/Image"},
          {"boxes", "/ground_truth/boxes_optical", "viper/Box3DArray"},
          {"objects", "/ground_truth/objects", "viper/ObjectArray"},
          {"draws", "/capture/draws", "viper/DrawList"},
          {"odom", "/ground_truth/odom", "nav_msgs/Odometry"},
          {"camera_info", "/capture/color/camera_info", "sensor_msgs/CameraInfo"}};
}

ExportRole* findExportRole(std::vector<ExportRole>& roles, const std::string& name) {
  for (ExportRole& r : roles)
    if (r.name == name) return &r;
  return nullptr;
}

const ExportRole& exportRole(const std::vector<ExportRole>& roles, const std::string& name) {
  for (const ExportRole& r : roles)
    if (r.name == name) return r;
  throw std::logic_error("no export role " + name);
}

ExportDispatch exportDispatch(const std::string& r, const sensor_msgs::ImageConstPtr& m) {
  if (r == "color") return [m](ViperExporter& e, uint64_t f) { return e.addColor(f, m); };
  if (r == "semantic") return [m](ViperExporter& e, uint64_t f) { return e.addSemantic(f, m); };
  if (r == "instance_ids") return [m](ViperExporter& e, uint64_t f) { return e.addInstanceIds(f, m); };
  if (r == "instances_viper") return [m](ViperExporter& e, uint64_t f) { return e.addInstancesViper(f, m); };
  if (r == "flow") return [m](ViperExporter& e, uint64_t f) { return e.addFlow(f, m, false); };
  return [m](ViperExporter& e, uint64_t f) { return e.addFlow(f, m, true); };
}
ExportDispatch exportDispatch(const std::string&, const Box3DArray::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addBoxesOptical(f, m); };
}
ExportDispatch exportDispatch(const std::string&, const ObjectArray::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addObjects(f, m); };
}
ExportDispatch exportDispatch(const std::string&, const DrawList::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addDraws(f, *m); };
}
ExportDispatch exportDispatch(const std::string&, const nav_msgs::Odometry::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addOdometry(f, *m); };
}
ExportDispatch exportDispatch(const std::string&, const sensor_msgs::CameraInfo::ConstPtr& m) {
  return [m](ViperExporter& e, uint64_t f) { return e.addCameraInfo(f, *m); };
}

bool exportDispatchFromBag(const std::string& r, const std::string& datatype, const BagReadMessage& mi,
                           ros::Time& stamp, ExportDispatch& dispatch) {
  auto take = [&](auto typed) {
    if (!typed) return false;
    stamp = typed->header.stamp;
    dispatch = exportDispatch(r, typed);
    return true;
  };
  if (datatype == "sensor_msgs/Image") return take(mi.instantiate<sensor_msgs::Image>());
  if (datatype == "viper/Box3DArray") return take(mi.instantiate<Box3DArray>());
  if (datatype == "viper/ObjectArray") return take(mi.instantiate<ObjectArray>());
  if (datatype == "viper/DrawList") return take(mi.instantiate<DrawList>());
  if (datatype == "nav_msgs/Odometry") return take(mi.instantiate<nav_msgs::Odometry>());
  if (datatype == "sensor_msgs/CameraInfo") return take(mi.instantiate<sensor_msgs::CameraInfo>());
  return false;
}

std::string stampText(const ros::Time& t) {
  char s[32];
  std::snprintf(s, sizeof s, "%u.%09u", t.sec, t.nsec);
  return s;
}

CameraSource cameraSourceOf(const std::string& word) {
  return word == "draws" ? CameraSource::kDraws : word == "odom" ? CameraSource::kOdometry : CameraSource::kNone;
}

std::string exportOptionsProblem(const ViperExportOptions& o, const std::string& palette, const std::string& camera) {
  if (o.image_extension != "png" && o.image_extension != "jpg") return "--img-format must be png or jpg";
  if (o.images.jpeg_quality < 0 || o.images.jpeg_quality > 100) return "--jpeg-quality must be 0..100";
  if (o.images.png_compression_level < 0 || o.images.png_compression_level > 9) return "--png-level must be 0..9";
  if (o.zip.deflate_level < 0 || o.zip.deflate_level > 9) return "--deflate-level must be 0..9";
  if (palette != "viper" && palette != "gray") return "--cls-palette must be viper or gray";
  if (camera != "auto" && camera != "draws" && camera != "odom" && camera != "none")
    return "--camera must be auto, draws, odom or none";
  if (!(o.near_m > 0 && o.far_m > o.near_m)) return "--near and --far need 0 < near < far";
  return "";
}

dataset::ClassPalette classPalette(const std::string& class_table_csv) {
  dataset::ClassPalette palette;
  const ClassTable table = ClassTable::load(class_table_csv);
  for (const ClassInfo& c : table.classes()) palette.push_back(c.rgb);
  return palette;
}

}  // namespace viper
