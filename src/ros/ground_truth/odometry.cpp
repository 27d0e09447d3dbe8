#include "viper/ros/ground_truth/odometry.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>

namespace viper {
Odometry::Odometry(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), private_nh_(pnh) {}

bool Odometry::start() {
  const std::string me = private_nh_.getNamespace();
  private_nh_.param<std::string>("map_frame", map_frame_, "map");
  private_nh_.param<std::string>("body_frame", body_frame_, "camera");
  private_nh_.param("publish_tf", publish_tf_, true);
  private_nh_.param("path_max_poses", path_max_poses_, 10000);
  if (map_frame_.empty() || body_frame_.empty() || map_frame_ == body_frame_) {
    ROS_FATAL("%s: ~map_frame ('%s') and ~body_frame ('%s') must be non-empty and differ", me.c_str(),
              map_frame_.c_str(), body_frame_.c_str());
    return false;
  }
  if (path_max_poses_ < 1) {
    ROS_ERROR("%s: ~path_max_poses must be >= 1 (got %d); using 10000", me.c_str(), path_max_poses_);
    path_max_poses_ = 10000;
  }
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  path_pub_ = nh_.advertise<nav_msgs::Path>("path", 1, true);
  if (publish_tf_) {
    tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  }
  path_.header.frame_id = map_frame_;
  draws_sub_ = nh_.subscribe("draws", 10, &Odometry::onDraws, this);
  return true;
}

void Odometry::onDraws(const DrawList::ConstPtr& draws) {
  const std::string& topic = draws_sub_.getTopic();
  const ros::Time stamp = draws->header.stamp;
  if (!last_stamp_.isZero() && stamp <= last_stamp_) {
    ROS_ERROR_THROTTLE(5, "%s: frame %lu stamp %.6f is not after the previous %.6f; frame dropped", topic.c_str(),
                       static_cast<unsigned long>(draws->frame_number), stamp.toSec(), last_stamp_.toSec());
    return;
  }
  CaptureFrame frame;
  fromDrawListMsg(*draws, frame);
  const auto camera = chooseFrameCamera(frame);
  if (!camera) {
    ROS_ERROR_THROTTLE(5, "%s: frame %lu has no draw with a view and a projection matrix; frame dropped",
                       topic.c_str(), static_cast<unsigned long>(draws->frame_number));
    return;
  }
  EgoPose pose;
  try {
    pose = egoPoseFromView(camera->view, stamp.toSec());
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "%s: frame %lu: %s; frame dropped", topic.c_str(),
                       static_cast<unsigned long>(draws->frame_number), e.what());
    return;
  }
  const std::string optical_frame = draws->header.frame_id.empty() ? "camera_optical" : draws->header.frame_id;
  if (publish_tf_) {
    tf_->sendTransform(toTransformMsg(pose.map_from_body, stamp, map_frame_, body_frame_));
    if (optical_frame != static_optical_frame_) {
      static_tf_->sendTransform(toTransformMsg(bodyFromOptical(), stamp, body_frame_, optical_frame));
      static_optical_frame_ = optical_frame;
    }
  }
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = map_frame_;
  odom.child_frame_id = body_frame_;
  odom.pose.pose = toPoseMsg(pose.map_from_body);
  if (last_) {
    const BodyTwist twist = bodyTwist(*last_, pose);
    odom.twist.twist.linear.x = twist.linear_mps.x(), odom.twist.twist.linear.y = twist.linear_mps.y();
    odom.twist.twist.linear.z = twist.linear_mps.z();
    odom.twist.twist.angular.x = twist.angular_radps.x(), odom.twist.twist.angular.y = twist.angular_radps.y();
    odom.twist.twist.angular.z = twist.angular_radps.z();
  }
  odom_pub_.publish(odom);

  geometry_msgs::PoseStamped ps;
  ps.header = odom.header;
  ps.pose = odom.pose.pose;
  path_.header.stamp = stamp;
  path_.poses.push_back(ps);
  if (static_cast<int>(path_.poses.size()) > path_max_poses_) path_.poses.erase(path_.poses.begin());
  path_pub_.publish(path_);
  last_ = pose;
  last_stamp_ = stamp;
}

}  // namespace viper
