// OpenGL matrices as programs build them, for tests: a perspective projection (gluPerspective)
// and a Z-up look-at view (gluLookAt).
#pragma once

#include "viper/capture/capture_frame.h"

#include <Eigen/Geometry>

#include <cmath>

namespace viper {
namespace test {

/// gluPerspective: vertical field of view in radians, aspect = width / height, near/far in metres.
inline GlMatrix glPerspective(double fovy_rad, double aspect, double near_m, double far_m) {
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  const double t = 1.0 / std::tan(fovy_rad / 2);
  p(0, 0) = t / aspect, p(1, 1) = t;
  p(2, 2) = -(far_m + near_m) / (far_m - near_m), p(2, 3) = -2 * far_m * near_m / (far_m - near_m);
  p(3, 2) = -1;
  return p.cast<float>();
}

/// gluLookAt with world Z up: the view matrix of a camera at `eye` looking at `target`.
inline GlMatrix glLookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d f = (target - eye).normalized(), s = f.cross(Eigen::Vector3d::UnitZ()).normalized(),
                        u = s.cross(f);
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.row(0).head<3>() = s, v.row(1).head<3>() = u, v.row(2).head<3>() = -f;
  v(0, 3) = -s.dot(eye), v(1, 3) = -u.dot(eye), v(2, 3) = f.dot(eye);
  return v.cast<float>();
}

}  // namespace test
}  // namespace viper
