// vo_baseline: a reference monocular visual odometry for the benchmark. Corners of a keyframe
// (goodFeaturesToTrack) tracked into each image (pyramidal Lucas-Kanade, forward-backward check);
// once they moved ~min_parallax_px, essential matrix with RANSAC and recoverPose, and a new
// keyframe; each step's translation scaled to the ground-truth step length, as is customary for
// monocular VO benchmarks. Topics and parameters: docs/baselines.md.
#pragma once

#include <Eigen/Geometry>
#include <nav_msgs/Odometry.h>
#include <opencv2/core.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// The vo_baseline node's class, shared by the node and the nodelet.
/// Subscribes `image`, `camera_info` and (with ~scale_from_ground_truth) `ground_truth_odom`;
/// publishes `odom` (nav_msgs/Odometry, pose of ~child_frame_id (body, REP 103: x forward, y left,
/// z up) in ~map_frame) with each image's stamp, from the second image on.
class VoBaseline {
 public:
  VoBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads parameters, subscribes and advertises; false after ROS_FATAL on impossible settings.
  bool start();

 private:
  void onImage(const sensor_msgs::Image::ConstPtr& msg);
  void onCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& msg);
  void onGroundTruth(const nav_msgs::Odometry::ConstPtr& msg);
  /// Processes images held back for their ground truth, in stamp order, as far as it is there.
  void processPending();
  void step(const sensor_msgs::Image::ConstPtr& msg, const cv::Mat& gray);
  void publish(const std_msgs::Header& header);

  ros::NodeHandle nh_, private_nh_;
  std::string map_frame_ = "map", child_frame_ = "vo_camera";
  bool scale_from_gt_ = true;
  int max_features_ = 1000, min_inliers_ = 30, max_pending_ = 30, queue_size_ = 10;
  double ransac_threshold_px_ = 1.0, fb_threshold_px_ = 0.5, min_parallax_px_ = 5.0;
  ros::Subscriber image_sub_, info_sub_, gt_sub_;
  ros::Publisher odom_pub_;

  std::optional<cv::Matx33d> K_;
  std::map<ros::Time, Eigen::Isometry3d> gt_;                     // stamp -> map_from_body
  std::map<ros::Time, sensor_msgs::Image::ConstPtr> pending_;     // images waiting for ground truth
  cv::Mat prev_gray_;
  ros::Time prev_stamp_;
  bool have_prev_ = false;
  Eigen::Isometry3d map_from_optical_ = Eigen::Isometry3d::Identity();
  // Keyframe: poses are estimated against it once its tracks have moved ~min_parallax_px_.
  cv::Mat kf_gray_;
  ros::Time kf_stamp_;
  Eigen::Isometry3d kf_map_from_optical_ = Eigen::Isometry3d::Identity();
  std::vector<cv::Point2f> kf_points_;
};

}  // namespace viper
