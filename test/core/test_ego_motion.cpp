#include "viper/core/ego_motion.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

// The view matrix a program builds for a camera at `eye` looking at `target` with Z up (gluLookAt).
GlMatrix lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target) {
  const Eigen::Vector3f f = (target - eye).normalized();
  const Eigen::Vector3f s = f.cross(Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f u = s.cross(f);
  GlMatrix v = GlMatrix::Identity();
  v.row(0).head<3>() = s.transpose();
  v.row(1).head<3>() = u.transpose();
  v.row(2).head<3>() = -f.transpose();
  v(0, 3) = -s.dot(eye), v(1, 3) = -u.dot(eye), v(2, 3) = f.dot(eye);
  return v;
}

TEST(EgoMotion, BodyFrameFollowsREP103) {
  // Camera at (1, 2, 1.5) looking along +Y in the world: body x (forward) = world +Y,
  // body y (left) = world -X, body z (up) = world +Z.
  const EgoPose p = egoPoseFromView(lookAt({1, 2, 1.5f}, {1, 12, 1.5f}), 3.0);
  EXPECT_LT((p.map_from_body.translation() - Eigen::Vector3d(1, 2, 1.5)).norm(), 1e-6);
  const Eigen::Matrix3d r = p.map_from_body.linear();
  EXPECT_LT((r.col(0) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-6);
  EXPECT_LT((r.col(1) - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-6);
  EXPECT_LT((r.col(2) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-6);
  // Optical: z forward = world +Y, x right = world +X, y down = world -Z.
  const Eigen::Matrix3d o = p.mapFromOptical().linear();
  EXPECT_LT((o.col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-6);
  EXPECT_LT((o.col(0) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-6);
  EXPECT_LT((o.col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-6);
}

TEST(EgoMotion, TwistOfAForwardTurningCamera) {
  const EgoPose a = egoPoseFromView(lookAt({0, 0, 1}, {10, 0, 1}), 0.0);
  // 0.5 s later: 5 m further along +X, heading turned by +0.2 rad (to the left).
  const Eigen::Vector3f eye(5, 0, 1);
  const EgoPose b = egoPoseFromView(lookAt(eye, eye + Eigen::Vector3f(std::cos(0.2f), std::sin(0.2f), 0)), 0.5);
  const BodyTwist t = bodyTwist(a, b);
  EXPECT_NEAR(t.angular_radps.z(), 0.4, 1e-5);
  EXPECT_NEAR(t.angular_radps.head<2>().norm(), 0.0, 1e-5);
  // In b's body frame the 5 m displacement along world X points forward-right.
  EXPECT_NEAR(t.linear_mps.x(), 10 * std::cos(0.2), 1e-4);
  EXPECT_NEAR(t.linear_mps.y(), -10 * std::sin(0.2), 1e-4);
  EXPECT_THROW(bodyTwist(b, a), std::invalid_argument);
}

TEST(EgoMotion, RejectsNonRigidAndNonFiniteViews) {
  GlMatrix v = lookAt({0, 0, 1}, {1, 0, 1});
  GlMatrix scaled = v;
  scaled.topLeftCorner<3, 3>() *= 2.0f;
  EXPECT_THROW(egoPoseFromView(scaled, 0), std::invalid_argument);
  GlMatrix nan = v;
  nan(1, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(egoPoseFromView(nan, 0), std::invalid_argument);
  EXPECT_THROW(egoPoseFromView(GlMatrix::Zero(), 0), std::invalid_argument);
}

}  // namespace
}  // namespace viper
