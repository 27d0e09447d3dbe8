// Poses and transforms: Eigen -> message -> Eigen, and the checks of a pose from elsewhere.
#include "viper/ros/conversions/pose_conversions.h"

#include <gtest/gtest.h>

#include <cmath>

namespace viper {
namespace {

Eigen::Isometry3d samplePose() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(12.5, -3.25, 1.75);
  return t;
}

void expectPoseNear(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-12) << a.matrix() << "\n" << b.matrix();
}

TEST(PoseConversions, PoseRoundTrip) {
  expectPoseNear(fromPoseMsg(toPoseMsg(samplePose())), samplePose());
  Eigen::Isometry3d checked;
  ASSERT_EQ(checkedPoseFromMsg(toPoseMsg(samplePose()), checked), "");
  expectPoseNear(checked, samplePose());
}

TEST(PoseConversions, TransformRoundTrip) {
  expectPoseNear(fromTransformMsg(toTransformMsg(samplePose())), samplePose());
  const geometry_msgs::TransformStamped tf = toTransformMsg(samplePose(), ros::Time(4, 2), "map", "camera");
  EXPECT_EQ(tf.header.frame_id, "map");
  EXPECT_EQ(tf.child_frame_id, "camera");
  EXPECT_EQ(tf.header.stamp, ros::Time(4, 2));
  expectPoseNear(fromTransformMsg(tf.transform), samplePose());
}

TEST(PoseConversions, OdometryPoseIsChecked) {
  nav_msgs::Odometry odom;
  odom.pose.pose = toPoseMsg(samplePose());
  Eigen::Isometry3d pose;
  ASSERT_EQ(poseFromOdometry(odom, pose), "");
  expectPoseNear(pose, samplePose());

  const Eigen::Isometry3d before = pose;
  odom.pose.pose.orientation.w = 0, odom.pose.pose.orientation.x = 0;
  odom.pose.pose.orientation.y = 0, odom.pose.pose.orientation.z = 0;
  EXPECT_NE(poseFromOdometry(odom, pose).find("norm 0"), std::string::npos);
  expectPoseNear(pose, before);  // left as it was
  odom.pose.pose = toPoseMsg(samplePose());
  odom.pose.pose.position.y = NAN;
  EXPECT_NE(poseFromOdometry(odom, pose).find("non-finite"), std::string::npos);
}

TEST(PoseConversions, UncheckedPoseNormalisesTheQuaternion) {
  geometry_msgs::Pose m = toPoseMsg(samplePose());
  m.orientation.x *= 2, m.orientation.y *= 2, m.orientation.z *= 2, m.orientation.w *= 2;
  expectPoseNear(fromPoseMsg(m), samplePose());
  Eigen::Isometry3d pose;
  EXPECT_NE(checkedPoseFromMsg(m, pose).find("norm 2"), std::string::npos);
}

TEST(PoseConversions, PoseFromOdometryQuarterTurn) {
  nav_msgs::Odometry m;
  m.pose.pose.position.x = 1, m.pose.pose.position.y = 2, m.pose.pose.position.z = 3;
  m.pose.pose.orientation.w = std::sqrt(0.5), m.pose.pose.orientation.z = std::sqrt(0.5);
  Eigen::Isometry3d p;
  ASSERT_EQ(poseFromOdometry(m, p), "");
  EXPECT_TRUE(p.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE((p.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  m.pose.pose.orientation.w = 0;
  m.pose.pose.orientation.z = 0;
  EXPECT_NE(poseFromOdometry(m, p).find("norm 0"), std::string::npos);
  m.pose.pose.orientation.w = 1;
  m.pose.pose.position.x = NAN;
  EXPECT_EQ(poseFromOdometry(m, p), "non-finite pose");
}

}  // namespace
}  // namespace viper
