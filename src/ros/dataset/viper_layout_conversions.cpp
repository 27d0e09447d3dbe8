#include "viper/ros/dataset/viper_layout_conversions.h"

#include "viper/ground_truth/semantic_overlay.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace viper {

dataset::RowMajor4 glProjectionFromK(const boost::array<double, 9>& K, uint32_t width, uint32_t height,
                                     double near_m, double far_m) {
  std::array<double, 9> k;
  std::copy(K.begin(), K.end(), k.begin());
  return glProjectionFromCameraMatrix(k, width, height, near_m, far_m);
}

ViperMessageBuilder::ViperMessageBuilder(const ViperTfFrames& frames, const ClassTable* classes)
    : frames_(frames), classes_(classes) {}

void ViperMessageBuilder::startSequence() {
  origin_inverse_.reset();
  last_pose_.reset();
  last_boxes_.clear();
}

geometry_msgs::TransformStamped ViperMessageBuilder::bodyToOptical(const ros::Time& stamp) const {
  return toTransformMsg(bodyFromOptical(), stamp, frames_.body, frames_.optical);
}

ViperFrameMessages ViperMessageBuilder::build(const dataset::ViperFrame& f, const ros::Time& stamp,
                                              const ViperTopicSelection& want) {
  ViperFrameMessages out;
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frames_.optical;
  auto image = [&](const dataset::Image8& im, const char* encoding) {
    return boost::make_shared<sensor_msgs::Image>(toImageMsg(im, header, encoding));
  };
  auto flowImage = [&](const dataset::FlowImage& fl) { return boost::make_shared<sensor_msgs::Image>(toFlowMsg(fl, header)); };
  const size_t n = static_cast<size_t>(f.width) * f.height;
  if (want.color && f.img) out.color = image(*f.img, "rgb8");
  if ((want.semantic || want.semantic_color) && (f.cls || f.inst)) {
    std::vector<uint8_t> classes = f.cls ? f.cls->data : dataset::viperInstanceClasses(*f.inst);
    if (want.semantic)
      out.semantic = boost::make_shared<sensor_msgs::Image>(imageMsg(header, f.width, f.height, "mono8", 1, classes.data()));
    if (want.semantic_color && classes_ != nullptr) {
      std::vector<uint8_t> rgb(3 * n);
      colorizeClasses(classes.data(), n, *classes_, rgb.data());
      out.semantic_color = boost::make_shared<sensor_msgs::Image>(imageMsg(header, f.width, f.height, "rgb8", 3, rgb.data()));
    }
  }
  if (want.instance_ids && f.inst) {
    const std::vector<int32_t> ids = dataset::viperInstanceIds(*f.inst);
    out.instance_ids = boost::make_shared<sensor_msgs::Image>(imageMsg(header, f.width, f.height, "32SC1", 4, ids.data()));
  }
  if (want.instances_viper && f.inst) out.instances_viper = image(*f.inst, "rgb8");
  if (want.flow_forward && f.flow) out.flow_forward = flowImage(*f.flow);
  if (want.flow_backward && f.flowbw) out.flow_backward = flowImage(*f.flowbw);

  std::optional<Eigen::Isometry3d> map_from_body;
  if (f.camera) {
    try {
      const Eigen::Isometry3d world_from_body = worldFromBody(f.camera->view);
      if (!origin_inverse_) origin_inverse_ = world_from_body.inverse();
      map_from_body = *origin_inverse_ * world_from_body;
    } catch (const std::invalid_argument& e) {
      out.problems.push_back("frame " + std::to_string(f.frame) + ": camera row: " + e.what() + "; no pose");
    }
    if (want.camera_info && f.width > 0) {
      try {
        const PinholeIntrinsics k = intrinsicsFromGlProjection(toGlMatrix(f.camera->projection), f.width, f.height);
        out.camera_info = boost::make_shared<sensor_msgs::CameraInfo>(cameraInfo(&k, f.width, f.height, header));
      } catch (const std::invalid_argument& e) {
        out.problems.push_back("frame " + std::to_string(f.frame) + ": camera row: " + e.what() + "; no camera_info");
      }
    }
  }
  if (map_from_body) {
    EgoPose pose;
    pose.time_s = stamp.toSec();
    pose.map_from_body = *map_from_body;
    out.map_to_body = toTransformMsg(*map_from_body, stamp, frames_.map, frames_.body);
    if (want.odom) {
      out.odom = boost::make_shared<nav_msgs::Odometry>();
      out.odom->header.stamp = stamp;
      out.odom->header.frame_id = frames_.map;
      out.odom->child_frame_id = frames_.body;
      out.odom->pose.pose = toPoseMsg(*map_from_body);
      if (last_pose_ && pose.time_s > last_pose_->time_s) {
        const BodyTwist twist = bodyTwist(*last_pose_, pose);
        auto& t = out.odom->twist.twist;
        t.linear.x = twist.linear_mps.x(), t.linear.y = twist.linear_mps.y(), t.linear.z = twist.linear_mps.z();
        t.angular.x = twist.angular_radps.x(), t.angular.y = twist.angular_radps.y(), t.angular.z = twist.angular_radps.z();
      }
    }
    last_pose_ = pose;
  }

  if (f.boxes && (want.boxes || want.boxes_optical)) {
    static const ClassTable kNoClasses;
    const ClassTable& classes = classes_ != nullptr ? *classes_ : kNoClasses;
    const Eigen::Isometry3d optical_from_gl = glCameraFromOptical().inverse();
    std::optional<Eigen::Isometry3d> map_from_optical;
    if (map_from_body) map_from_optical = *map_from_body * bodyFromOptical();
    out.boxes_optical = boost::make_shared<Box3DArray>();
    out.boxes_optical->header = header;
    if (map_from_optical) {
      out.boxes = boost::make_shared<Box3DArray>();
      out.boxes->header = header;
      out.boxes->header.frame_id = frames_.map;
    }
    std::map<int32_t, Seen> seen;
    const double t = stamp.toSec();
    for (const dataset::ViperBoxRow& row : *f.boxes) {
      OrientedBox in_optical;
      try {
        in_optical = boxInGlCamera(row).transformed(optical_from_gl);
      } catch (const std::invalid_argument& e) {
        out.problems.push_back("frame " + std::to_string(f.frame) + ": box of instance " +
                               std::to_string(row.instance_id) + ": " + e.what() + "; box skipped");
        continue;
      }
      const int32_t id = static_cast<int32_t>(row.instance_id);
      const uint8_t class_id = static_cast<uint8_t>(row.class_id);
      Eigen::Vector3d velocity_map = Eigen::Vector3d::Zero();
      if (map_from_optical) {
        const OrientedBox in_map = in_optical.transformed(*map_from_optical);
        const auto last = last_boxes_.find(id);
        if (last != last_boxes_.end() && t > last->second.time_s)
          velocity_map = (in_map.center - last->second.center_map) / (t - last->second.time_s);
        seen[id] = {in_map.center, t};
        out.boxes->boxes.push_back(toBox3DMsg(in_map, id, class_id, classes, velocity_map));
      }
      const Eigen::Vector3d velocity_optical =
          map_from_optical ? Eigen::Vector3d(map_from_optical->linear().transpose() * velocity_map) : Eigen::Vector3d::Zero();
      out.boxes_optical->boxes.push_back(toBox3DMsg(in_optical, id, class_id, classes, velocity_optical));
    }
    last_boxes_.swap(seen);
    if (!want.boxes) out.boxes.reset();
    if (!want.boxes_optical) out.boxes_optical.reset();
  }
  return out;
}

}  // namespace viper
