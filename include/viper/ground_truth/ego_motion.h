// Ego-motion: the camera pose is the inverse of the view matrix (docs/ground_truth.md), expressed in
// REP 103/105 frames: `map` (the program's world, Z up), the camera body frame (x forward, y left,
// z up) and the optical frame (x right, y down, z forward).
#pragma once

#include "viper/capture/capture_frame.h"

#include <Eigen/Geometry>

namespace viper {

/// Fixed rotation of the optical frame in the body frame: p_body = bodyFromOptical() * p_optical.
Eigen::Isometry3d bodyFromOptical();

/// Camera pose at one instant.
struct EgoPose {
  double time_s = 0.0;
  Eigen::Isometry3d map_from_body = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d mapFromOptical() const { return map_from_body * bodyFromOptical(); }
};

/// Pose of the camera body in `map` from an OpenGL view matrix (world -> OpenGL camera).
/// Throws std::invalid_argument if the matrix is not finite or not rigid (its rotation part must be
/// orthonormal within 1e-4 and its last row 0 0 0 1).
EgoPose egoPoseFromView(const GlMatrix& view, double time_s);

/// Body-frame velocity between two poses (nav_msgs/Odometry convention: twist in the child frame),
/// by finite difference over their time step, expressed in the later pose's body frame.
struct BodyTwist {
  Eigen::Vector3d linear_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_radps = Eigen::Vector3d::Zero();
};
/// Throws std::invalid_argument if `later.time_s <= earlier.time_s`.
BodyTwist bodyTwist(const EgoPose& earlier, const EgoPose& later);

}  // namespace viper
