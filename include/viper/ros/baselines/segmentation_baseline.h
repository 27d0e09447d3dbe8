// segmentation_baseline: the reference semantic and instance segmentation for the benchmark. A
// small fully convolutional network (scripts/train_segmentation.py, run with OpenCV's DNN module:
// include/viper/baselines/segmentation_model.h) labels every pixel of the camera image; the
// connected regions of its instance classes are the instances. Topics and parameters:
// docs/baselines.md.
#pragma once

#include "viper/baselines/segmentation_model.h"

#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <memory>
#include <string>
#include <vector>

namespace viper {

/// The segmentation_baseline node's class, shared by the node and the nodelet.
/// Subscribes `image` (rgb8, bgr8, rgba8, bgra8 or mono8); publishes, with the image's header,
/// `semantic` (mono8 class ids of ~class_table, the image's size) and, with ~instances,
/// `instances` (viper/InstancePredictionArray: one per connected region of an instance class,
/// scored by its mean class probability, masks cut to their boxes).
class SegmentationBaseline {
 public:
  SegmentationBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Reads parameters, loads the model, subscribes and advertises; false after ROS_FATAL when the
  /// model or the class table cannot be used.
  bool start();

 private:
  void onImage(const sensor_msgs::Image::ConstPtr& msg);
  void publishInstances(const std_msgs::Header& header, const Segmentation& segmentation);

  ros::NodeHandle nh_, private_nh_;
  int min_instance_px_ = 10, queue_size_ = 10;
  bool instances_ = true;
  std::unique_ptr<SegmentationModel> model_;
  std::vector<bool> instance_class_;
  ros::Subscriber image_sub_;
  ros::Publisher semantic_pub_, instances_pub_;
};

}  // namespace viper
