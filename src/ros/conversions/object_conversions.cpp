#include "viper/ros/conversions/object_conversions.h"

#include "viper/ros/conversions/pose_conversions.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cstdint>
#include <limits>

namespace viper {

std::string className(const ClassTable& classes, int class_id) {
  return class_id >= 0 && static_cast<size_t>(class_id) < classes.size() ? classes.at(class_id).name
                                                                         : "class_" + std::to_string(class_id);
}

ObjectArray toObjectArrayMsg(const std::vector<TrackedObject>& objects, const ClassTable& classes,
                             const std_msgs::Header& header) {
  ObjectArray msg;
  msg.header = header;
  msg.objects.reserve(objects.size());
  for (const TrackedObject& t : objects) {
    const FrameObject& o = t.object;
    Object m;
    m.track_id = t.track_id;
    m.class_id = o.class_id;
    m.class_name = className(classes, o.class_id);
    m.draws = o.draws;
    m.pixel_count = o.pixel_count;
    if (o.pixel_count > 0) {
      m.box_2d.x_offset = static_cast<uint32_t>(o.x_min);
      m.box_2d.y_offset = static_cast<uint32_t>(o.y_min);
      m.box_2d.width = static_cast<uint32_t>(o.x_max - o.x_min + 1);
      m.box_2d.height = static_cast<uint32_t>(o.y_max - o.y_min + 1);
    }
    const Eigen::Matrix3d linear = o.world.topLeftCorner<3, 3>().cast<double>();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
    if (r.determinant() < 0) r = -r;
    m.world_pose = toPoseMsg(o.world.block<3, 1>(0, 3).cast<double>(), Eigen::Quaterniond(r).normalized());
    msg.objects.push_back(std::move(m));
  }
  return msg;
}

namespace {

int clampedToInt(uint64_t v) { return static_cast<int>(std::min<uint64_t>(v, std::numeric_limits<int>::max())); }

}  // namespace

std::vector<TrackedObject> fromObjectArrayMsg(const ObjectArray& msg) {
  std::vector<TrackedObject> out;
  out.reserve(msg.objects.size());
  for (const Object& m : msg.objects) {
    TrackedObject t;
    t.track_id = m.track_id;
    FrameObject& o = t.object;
    o.class_id = m.class_id;
    o.is_thing = m.track_id > 0;
    o.draws = m.draws;
    o.pixel_count = m.pixel_count;
    if (m.pixel_count > 0) {
      // The message's offsets and sizes are unsigned 32-bit: summed in 64 bits and cut at INT_MAX.
      o.x_min = clampedToInt(m.box_2d.x_offset), o.y_min = clampedToInt(m.box_2d.y_offset);
      o.x_max = clampedToInt(uint64_t(m.box_2d.x_offset) + m.box_2d.width) - 1;
      o.y_max = clampedToInt(uint64_t(m.box_2d.y_offset) + m.box_2d.height) - 1;
    }
    o.world = fromPoseMsg(m.world_pose).matrix().cast<float>();
    out.push_back(std::move(t));
  }
  return out;
}

Box3D toBox3DMsg(const OrientedBox& box, int32_t id, uint8_t class_id, const ClassTable& classes,
                 const Eigen::Vector3d& velocity) {
  Box3D m;
  m.id = id;
  m.class_id = class_id;
  m.class_name = className(classes, class_id);
  m.pose = toPoseMsg(box.center, box.orientation);
  m.size.x = box.size.x(), m.size.y = box.size.y(), m.size.z = box.size.z();
  m.velocity.linear.x = velocity.x(), m.velocity.linear.y = velocity.y(), m.velocity.linear.z = velocity.z();
  return m;
}

OrientedBox fromBox3DMsg(const Box3D& m) {
  OrientedBox b;
  const Eigen::Isometry3d pose = fromPoseMsg(m.pose);
  b.center = pose.translation();
  b.orientation = Eigen::Quaterniond(pose.linear());
  b.size = Eigen::Vector3d(m.size.x, m.size.y, m.size.z);
  return b;
}

visualization_msgs::MarkerArray boxMarkers(const Box3DArray& boxes, const ClassTable& classes) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker clear;
  clear.header = boxes.header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);
  int next_id = 0;
  for (const Box3D& b : boxes.boxes) {
    std::array<uint8_t, 3> rgb{{255, 255, 255}};
    if (b.class_id < classes.size()) rgb = classes.at(b.class_id).rgb;
    visualization_msgs::Marker cube;
    cube.header = boxes.header;
    cube.ns = "boxes";
    cube.id = next_id++;
    cube.type = visualization_msgs::Marker::CUBE;
    cube.action = visualization_msgs::Marker::ADD;
    cube.pose = b.pose;
    cube.scale = b.size;
    cube.color.r = rgb[0] / 255.0f, cube.color.g = rgb[1] / 255.0f, cube.color.b = rgb[2] / 255.0f;
    cube.color.a = 0.45f;
    out.markers.push_back(cube);
    visualization_msgs::Marker label = cube;
    label.ns = "labels";
    label.id = next_id++;
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.text = b.class_name + " " + std::to_string(b.id);
    label.scale.x = label.scale.y = 0.0;
    label.scale.z = 0.5;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    // Above the box: half its extent along the box's own z, which is up for upright objects.
    const Eigen::Isometry3d pose = fromPoseMsg(b.pose);
    const Eigen::Vector3d top = pose * Eigen::Vector3d(0, 0, 0.5 * b.size.z + 0.4);
    label.pose = toPoseMsg(top, Eigen::Quaterniond::Identity());
    out.markers.push_back(label);
  }
  return out;
}

}  // namespace viper
