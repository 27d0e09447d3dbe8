#include "viper/ros/conversions/pose_conversions.h"

#include <cmath>

namespace viper {
namespace {

Eigen::Isometry3d isometry(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

}  // namespace

geometry_msgs::Pose toPoseMsg(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  geometry_msgs::Pose m;
  m.position.x = p.x(), m.position.y = p.y(), m.position.z = p.z();
  m.orientation.x = q.x(), m.orientation.y = q.y(), m.orientation.z = q.z(), m.orientation.w = q.w();
  return m;
}

geometry_msgs::Pose toPoseMsg(const Eigen::Isometry3d& pose) {
  return toPoseMsg(pose.translation(), Eigen::Quaterniond(pose.linear()).normalized());
}

Eigen::Isometry3d fromPoseMsg(const geometry_msgs::Pose& m) {
  return isometry(Eigen::Vector3d(m.position.x, m.position.y, m.position.z),
                  Eigen::Quaterniond(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z));
}

std::string checkedPoseFromMsg(const geometry_msgs::Pose& m, Eigen::Isometry3d& pose) {
  const Eigen::Vector3d t(m.position.x, m.position.y, m.position.z);
  const Eigen::Quaterniond q(m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z);
  if (!t.allFinite() || !q.coeffs().allFinite()) return "non-finite pose";
  if (std::abs(q.norm() - 1.0) > 1e-3)
    return "orientation quaternion has norm " + std::to_string(q.norm()) + ", expected 1";
  pose = isometry(t, q);
  return "";
}

std::string poseFromOdometry(const nav_msgs::Odometry& msg, Eigen::Isometry3d& pose) {
  return checkedPoseFromMsg(msg.pose.pose, pose);
}

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& t) {
  const geometry_msgs::Pose p = toPoseMsg(t);
  geometry_msgs::Transform m;
  m.translation.x = p.position.x, m.translation.y = p.position.y, m.translation.z = p.position.z;
  m.rotation = p.orientation;
  return m;
}

Eigen::Isometry3d fromTransformMsg(const geometry_msgs::Transform& m) {
  return isometry(Eigen::Vector3d(m.translation.x, m.translation.y, m.translation.z),
                  Eigen::Quaterniond(m.rotation.w, m.rotation.x, m.rotation.y, m.rotation.z));
}

geometry_msgs::TransformStamped toTransformMsg(const Eigen::Isometry3d& t, const ros::Time& stamp,
                                               const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = stamp;
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform = toTransformMsg(t);
  return m;
}

}  // namespace viper
