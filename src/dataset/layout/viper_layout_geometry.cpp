#include "viper/dataset/viper_layout_geometry.h"

#include "viper/ground_truth/ego_motion.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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

dataset::RowMajor4 glProjectionFromCameraMatrix(const std::array<double, 9>& K, uint32_t width, uint32_t height,
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

Eigen::Isometry3d glCameraFromOptical() { return glFromOptical(); }

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

}  // namespace viper
