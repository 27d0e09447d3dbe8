#include "viper/ros/ground_truth/odometry_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <boost/make_shared.hpp>

#include <cstdio>
#include <stdexcept>

namespace viper {

OdometryStep::OdometryStep(const OdometrySettings& settings) : settings_(settings) {
  if (settings_.map_frame.empty() || settings_.body_frame.empty() || settings_.map_frame == settings_.body_frame)
    throw std::invalid_argument("map_frame ('" + settings_.map_frame + "') and body_frame ('" + settings_.body_frame +
                                "') must be non-empty and differ");
  if (settings_.path_max_poses < 1)
    throw std::invalid_argument("path_max_poses must be >= 1 (got " + std::to_string(settings_.path_max_poses) + ")");
  path_.header.frame_id = settings_.map_frame;
}

bool OdometryStep::process(const DrawList& draws, Output& out, StepProblems& problems) {
  out = Output();
  const ros::Time stamp = draws.header.stamp;
  const unsigned long number = draws.frame_number;
  if (!last_stamp_.isZero() && stamp <= last_stamp_) {
    char text[160];
    std::snprintf(text, sizeof text, ": frame %lu stamp %.6f is not after the previous %.6f; frame dropped", number,
                  stamp.toSec(), last_stamp_.toSec());
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "stamp_order", text});
    return false;
  }
  CaptureFrame& frame = frame_;  // kept: its draws' storage is reused
  fromDrawListMsg(draws, frame);
  const auto camera = chooseFrameCamera(frame);
  if (!camera) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "no_camera",
                        ": frame " + std::to_string(number) +
                            " has no draw with a view and a projection matrix; frame dropped"});
    return false;
  }
  EgoPose pose;
  try {
    pose = egoPoseFromView(camera->view, stamp.toSec());
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "view",
                        ": frame " + std::to_string(number) + ": " + e.what() + "; frame dropped"});
    return false;
  }
  const std::string optical_frame = draws.header.frame_id.empty() ? "camera_optical" : draws.header.frame_id;
  out.map_to_body = toTransformMsg(pose.map_from_body, stamp, settings_.map_frame, settings_.body_frame);
  out.body_to_optical = toTransformMsg(bodyFromOptical(), stamp, settings_.body_frame, optical_frame);
  out.optical_changed = optical_frame != optical_frame_;
  optical_frame_ = optical_frame;

  out.odom = boost::make_shared<nav_msgs::Odometry>();
  nav_msgs::Odometry& odom = *out.odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = settings_.map_frame;
  odom.child_frame_id = settings_.body_frame;
  odom.pose.pose = toPoseMsg(pose.map_from_body);
  if (last_) {
    const BodyTwist twist = bodyTwist(*last_, pose);
    odom.twist.twist.linear.x = twist.linear_mps.x(), odom.twist.twist.linear.y = twist.linear_mps.y();
    odom.twist.twist.linear.z = twist.linear_mps.z();
    odom.twist.twist.angular.x = twist.angular_radps.x(), odom.twist.twist.angular.y = twist.angular_radps.y();
    odom.twist.twist.angular.z = twist.angular_radps.z();
  }
  if (settings_.make_path) {
    geometry_msgs::PoseStamped ps;
    ps.header = odom.header;
    ps.pose = odom.pose.pose;
    path_.header.stamp = stamp;
    path_.poses.push_back(ps);
    if (static_cast<int>(path_.poses.size()) > settings_.path_max_poses) path_.poses.erase(path_.poses.begin());
    out.path = boost::make_shared<const nav_msgs::Path>(path_);
  }
  last_ = pose;
  last_stamp_ = stamp;
  return true;
}

}  // namespace viper
