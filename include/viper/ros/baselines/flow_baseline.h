// flow_baseline: a reference optical-flow method for the benchmark. OpenCV's dense flow (DIS or
// Farneback) between consecutive camera images, published in the ground-truth flow node's
// convention. Topics and parameters: docs/baselines.md.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <string>

namespace viper {

/// The flow_baseline node's class, shared by the node and the nodelet.
/// Subscribes `image` (rgb8, bgr8, rgba8, bgra8 or mono8); publishes `flow` (32FC2, pixels, u right,
/// v down) from frame f to f+1 with f's stamp and frame_id, when f+1 arrives.
class FlowBaseline {
 public:
  FlowBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads parameters, subscribes and advertises; false after ROS_FATAL on an unknown ~method.
  bool start();

 private:
  void onImage(const sensor_msgs::Image::ConstPtr& msg);

  ros::NodeHandle nh_, private_nh_;
  std::string method_ = "dis";
  int queue_size_ = 10;
  ros::Subscriber image_sub_;
  ros::Publisher flow_pub_;
  cv::Ptr<cv::DISOpticalFlow> dis_;
  cv::Mat prev_gray_;
  std_msgs::Header prev_header_;
};

}  // namespace viper
