#include "viper/ground_truth/ego_motion.h"

#include "../common/gl_matrices.h"

#include <gtest/gtest.h>

namespace viper {
namespace {

using test::glLookAt;

TEST(EgoMotion, BodyFrameFollowsREP103) {
  // Camera at (1, 2, 1.5) looking along +Y in the world: body x (forward) = world +Y,
  // body y (left) = world -X, body z (up) = world +Z.
  const EgoPose p = egoPoseFromView(glLookAt({1, 2, 1.5}, {1, 12, 1.5}), 3.0);
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
  const EgoPose a = egoPoseFromView(glLookAt({0, 0, 1}, {10, 0, 1}), 0.0);
  // 0.5 s later: 5 m further along +X, heading turned by +0.2 rad (to the left).
  const Eigen::Vector3d eye(5, 0, 1);
  const EgoPose b = egoPoseFromView(glLookAt(eye, eye + Eigen::Vector3d(std::cos(0.2), std::sin(0.2), 0)), 0.5);
  const BodyTwist t = bodyTwist(a, b);
  EXPECT_NEAR(t.angular_radps.z(), 0.4, 1e-5);
  EXPECT_NEAR(t.angular_radps.head<2>().norm(), 0.0, 1e-5);
  // In b's body frame the 5 m displacement along world X points forward-right.
  EXPECT_NEAR(t.linear_mps.x(), 10 * std::cos(0.2), 1e-4);
  EXPECT_NEAR(t.linear_mps.y(), -10 * std::sin(0.2), 1e-4);
  EXPECT_THROW(bodyTwist(b, a), std::invalid_argument);
}

TEST(EgoMotion, RejectsNonRigidAndNonFiniteViews) {
  GlMatrix v = glLookAt({0, 0, 1}, {1, 0, 1});
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
