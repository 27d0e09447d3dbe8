#include "viper/ros/dataset/viper_layout_conversions.h"

#include "viper/ground_truth/semantic_overlay.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <Eigen/SVD>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace viper {
namespace {

// Body axes (x forward, y left, z up) written in OpenGL camera axes (x right, y up, -z forward).
Eigen::Isometry3d glFromBody() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << 0, -1, 0,
                0, 0, 1,
               -1, 0, 0;
  return t;
}

Eigen::Isometry3d glFromOptical() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = opticalFromGlCamera().transpose();
  return t;
}

Eigen::Isometry3d rigidOf(const dataset::RowMajor4& m, const char* what) {
  const Eigen::Matrix4d e = toEigen(m);
  if (!e.allFinite()) throw std::invalid_argument(std::string(what) + " is not finite");
  const Eigen::Matrix3d r = e.topLeftCorner<3, 3>();
  const double ortho = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double last_row = (e.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff();
  if (ortho > 1e-4 || r.determinant() < 0 || last_row > 1e-6)
    throw std::invalid_argument(std::string(what) + " is not rigid (rotation off by " + std::to_string(ortho) +
                                ", last row off by " + std::to_string(last_row) + ")");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  // Re-orthonormalise so products of many poses stay rigid.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  t.linear() = svd.matrixU() * svd.matrixV().transpose();
  t.translation() = e.block<3, 1>(0, 3);
  return t;
}

}  // namespace

Eigen::Matrix4d toEigen(const dataset::RowMajor4& m) {
  Eigen::Matrix4d e;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e(r, c) = m[4 * r + c];
  return e;
}

dataset::RowMajor4 toRowMajor(const Eigen::Matrix4d& e) {
  dataset::RowMajor4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[4 * r + c] = e(r, c);
  return m;
}

dataset::RowMajor4 toRowMajor(const GlMatrix& g) { return toRowMajor(Eigen::Matrix4d(g.cast<double>())); }

GlMatrix toGlMatrix(const dataset::RowMajor4& m) { return toEigen(m).cast<float>(); }

Eigen::Isometry3d worldFromBody(const dataset::RowMajor4& view) {
  return rigidOf(view, "view matrix").inverse() * glFromBody();
}

dataset::RowMajor4 relativeView(const dataset::RowMajor4& view, const dataset::RowMajor4& origin) {
  const Eigen::Isometry3d origin_inverse = rigidOf(origin, "first view matrix").inverse();
  Eigen::Matrix4d rel = toEigen(view) * origin_inverse.matrix();
  rel.row(3) << 0, 0, 0, 1;  // exact, as view matrices have it
  return toRowMajor(rel);
}

dataset::RowMajor4 viewFromBodyPose(const Eigen::Isometry3d& world_from_body) {
  Eigen::Matrix4d view = (world_from_body * glFromBody().inverse()).inverse().matrix();
  view.row(3) << 0, 0, 0, 1;
  return toRowMajor(view);
}

dataset::RowMajor4 glProjectionFromK(const boost::array<double, 9>& K, uint32_t width, uint32_t height,
                                     double near_m, double far_m) {
  const double fx = K[0], skew = K[1], cx = K[2], fy = K[4], cy = K[5];
  if (!(fx > 0) || !(fy > 0) || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
    throw std::invalid_argument("camera_info K is not a pinhole camera matrix (fx, fy > 0, last row 0 0 1)");
  if (width == 0 || height == 0) throw std::invalid_argument("camera_info has no image size");
  if (!(near_m > 0) || !(far_m > near_m)) throw std::invalid_argument("depth range must satisfy 0 < near < far");
  const double w = width, h = height;
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2 * fx / w;
  p(0, 1) = -2 * skew / w;
  p(0, 2) = 1 - 2 * (cx + 0.5) / w;
  p(1, 1) = 2 * fy / h;
  p(1, 2) = 2 * (cy + 0.5) / h - 1;
  p(2, 2) = -(far_m + near_m) / (far_m - near_m);
  p(2, 3) = -2 * far_m * near_m / (far_m - near_m);
  p(3, 2) = -1;
  return toRowMajor(p);
}

OrientedBox boxInGlCamera(const dataset::ViperBoxRow& row) {
  const Eigen::Matrix4d m = toEigen(row.model_to_camera);
  if (!m.allFinite() || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6)
    throw std::invalid_argument("model-to-camera matrix is not affine (last row must be 0 0 0 1)");
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  const Eigen::Vector3d scale = linear.colwise().norm();
  if (!(scale.minCoeff() > 1e-12) || std::abs(linear.determinant()) < 1e-12)
    throw std::invalid_argument("model-to-camera matrix is singular");
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) r = -r;
  const Eigen::Vector3d lo(row.box_3d[0], row.box_3d[1], row.box_3d[2]);
  const Eigen::Vector3d hi(row.box_3d[3], row.box_3d[4], row.box_3d[5]);
  OrientedBox box;
  box.center = (m * (0.5 * (lo + hi)).homogeneous()).head<3>();
  box.orientation = Eigen::Quaterniond(r).normalized();
  box.size = (hi - lo).cwiseAbs().cwiseProduct(scale);
  return box;
}

dataset::ViperBoxRow viperBoxRow(const OrientedBox& box, int class_id, int64_t instance_id,
                                 const std::array<double, 4>& box_2d) {
  dataset::ViperBoxRow row;
  row.class_id = class_id;
  row.instance_id = instance_id;
  row.box_2d = box_2d;
  const Eigen::Vector3d half = 0.5 * box.size;
  row.box_3d = {{-half.x(), -half.y(), -half.z(), half.x(), half.y(), half.z()}};
  Eigen::Isometry3d optical_from_model = Eigen::Isometry3d::Identity();
  optical_from_model.linear() = box.orientation.normalized().toRotationMatrix();
  optical_from_model.translation() = box.center;
  Eigen::Matrix4d m = (glFromOptical() * optical_from_model).matrix();
  m.row(3) << 0, 0, 0, 1;
  row.model_to_camera = toRowMajor(m);
  return row;
}

std::map<int32_t, std::array<double, 4>> instanceBoxes(const int32_t* ids, uint32_t width, uint32_t height) {
  std::map<int32_t, std::array<double, 4>> boxes;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const int32_t id = ids[static_cast<size_t>(y) * width + x];
      if (id <= 0) continue;
      auto [it, fresh] = boxes.try_emplace(id, std::array<double, 4>{{double(x), double(y), double(x), double(y)}});
      if (fresh) continue;
      auto& b = it->second;
      b[0] = std::min<double>(b[0], x), b[1] = std::min<double>(b[1], y);
      b[2] = std::max<double>(b[2], x), b[3] = std::max<double>(b[3], y);
    }
  return boxes;
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
    const Eigen::Isometry3d optical_from_gl = glFromOptical().inverse();
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
