#include "viper/ros/baselines/segmentation_baseline.h"
#include "viper/ros/node_params.h"

#include "viper/ros/baselines/image_input.h"
#include "viper/ros/conversions/image_conversions.h"

#include <ros/package.h>
#include <viper/InstancePredictionArray.h>

#include <boost/make_shared.hpp>

namespace viper {

SegmentationBaseline::SegmentationBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh) {}

bool SegmentationBaseline::start() {
  const std::string package = ros::package::getPath("viper");
  std::string model_path, class_path;
  private_nh_.param<std::string>("model", model_path, package + "/models/segmentation_all.onnx");
  private_nh_.param<std::string>("class_table", class_path, package + "/config/viper_classes.csv");
  int width = 256, height = 144;
  private_nh_.param("input_width", width, width);
  private_nh_.param("input_height", height, height);
  try {
    const ClassTable classes = ClassTable::load(class_path);
    instance_class_ = classes.instanceEvalMask();
    model_ = std::make_unique<SegmentationModel>(model_path, classes, cv::Size(width, height));
  } catch (const std::exception& e) {
    ROS_FATAL("segmentation_baseline: %s (set ~model to an ONNX file of scripts/train_segmentation.py, "
              "~class_table to its class table, ~input_width/~input_height to multiples of 8)", e.what());
    return false;
  }
  private_nh_.param("instances", instances_, instances_);
  private_nh_.param("min_instance_px", min_instance_px_, min_instance_px_);
  if (min_instance_px_ < 1) {
    ROS_ERROR("segmentation_baseline: ~min_instance_px must be >= 1 (got %d); using 10", min_instance_px_);
    min_instance_px_ = 10;
  }
  queue_size_ = queueSizeParam(private_nh_, queue_size_);
  const auto q = static_cast<uint32_t>(queue_size_);
  semantic_pub_ = nh_.advertise<sensor_msgs::Image>("semantic", q);
  if (instances_) instances_pub_ = nh_.advertise<InstancePredictionArray>("instances", q);
  image_sub_ = nh_.subscribe("image", q, &SegmentationBaseline::onImage, this);
  ROS_INFO("segmentation_baseline: %s (%d classes at %dx%d) from %s to %s%s", model_path.c_str(),
           model_->outputClasses(), width, height, image_sub_.getTopic().c_str(), semantic_pub_.getTopic().c_str(),
           instances_ ? (" and " + instances_pub_.getTopic()).c_str() : "");
  return true;
}

void SegmentationBaseline::onImage(const sensor_msgs::Image::ConstPtr& msg) {
  try {
    cv::Mat rgb;
    std::string error;
    if (!rgbFromImage(*msg, rgb, error)) {
      ROS_ERROR_THROTTLE(5, "segmentation_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                         msg->header.stamp.toSec(), error.c_str());
      return;
    }
    const Segmentation s = model_->segment(rgb);
    semantic_pub_.publish(imageMsgPtr(msg->header, s.class_ids.cols, s.class_ids.rows, "mono8", 1, s.class_ids.data));
    if (instances_) publishInstances(msg->header, s);
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "segmentation_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                       msg->header.stamp.toSec(), e.what());
  }
}

void SegmentationBaseline::publishInstances(const std_msgs::Header& header, const Segmentation& segmentation) {
  auto out = boost::make_shared<InstancePredictionArray>();
  out->header = header;
  for (const InstanceSegment& inst : instancesFromSegmentation(segmentation, instance_class_, min_instance_px_)) {
    InstancePrediction p;
    p.class_id = inst.class_id;
    p.score = inst.score;
    p.x_offset = static_cast<uint32_t>(inst.box.x);
    p.y_offset = static_cast<uint32_t>(inst.box.y);
    const cv::Mat mask = inst.mask.clone();  // continuous rows
    p.mask = imageMsg(header, mask.cols, mask.rows, "mono8", 1, mask.data);
    out->instances.push_back(std::move(p));
  }
  instances_pub_.publish(out);
}

}  // namespace viper
