#include "viper/ros/baselines/flow_baseline.h"
#include "viper/ros/node_params.h"

#include "viper/ros/baselines/image_input.h"

#include <sensor_msgs/image_encodings.h>

#include <cstring>

namespace viper {

FlowBaseline::FlowBaseline(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh) {}

bool FlowBaseline::start() {
  private_nh_.param("method", method_, method_);
  if (method_ == "dis") {
    dis_ = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  } else if (method_ != "farneback") {
    ROS_FATAL("flow_baseline: ~method '%s' unknown (dis or farneback)", method_.c_str());
    return false;
  }
  queue_size_ = queueSizeParam(private_nh_, queue_size_);
  const auto q = static_cast<uint32_t>(queue_size_);
  flow_pub_ = nh_.advertise<sensor_msgs::Image>("flow", q);
  image_sub_ = nh_.subscribe("image", q, &FlowBaseline::onImage, this);
  ROS_INFO("flow_baseline: %s flow from %s to %s", method_.c_str(), image_sub_.getTopic().c_str(),
           flow_pub_.getTopic().c_str());
  return true;
}

void FlowBaseline::onImage(const sensor_msgs::Image::ConstPtr& msg) {
  try {
    cv::Mat gray;
    std::string error;
    if (!grayFromImage(*msg, gray, error)) {
      ROS_ERROR_THROTTLE(5, "flow_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                         msg->header.stamp.toSec(), error.c_str());
      return;
    }
    if (!prev_gray_.empty() && msg->header.stamp <= prev_header_.stamp) {
      ROS_ERROR_THROTTLE(5, "flow_baseline: %s: frame %.6f dropped: stamp not after the previous %.6f",
                         image_sub_.getTopic().c_str(), msg->header.stamp.toSec(), prev_header_.stamp.toSec());
      return;
    }
    if (!prev_gray_.empty() && gray.size() != prev_gray_.size()) {
      // A new size starts a new sequence: no flow across it.
      ROS_ERROR_THROTTLE(5, "flow_baseline: %s: size changed from %dx%d to %dx%d at %.6f: no flow for that pair",
                         image_sub_.getTopic().c_str(), prev_gray_.cols, prev_gray_.rows, gray.cols, gray.rows,
                         msg->header.stamp.toSec());
    } else if (!prev_gray_.empty()) {
      cv::Mat flow;
      if (dis_) dis_->calc(prev_gray_, gray, flow);
      else cv::calcOpticalFlowFarneback(prev_gray_, gray, flow, 0.5, 5, 15, 3, 5, 1.1, 0);
      sensor_msgs::Image out;
      out.header = prev_header_;
      out.width = flow.cols, out.height = flow.rows;
      out.encoding = sensor_msgs::image_encodings::TYPE_32FC2;
      out.is_bigendian = false;
      out.step = flow.cols * 2 * sizeof(float);
      out.data.resize(static_cast<size_t>(out.step) * out.height);
      for (int y = 0; y < flow.rows; ++y) std::memcpy(&out.data[y * out.step], flow.ptr(y), out.step);
      flow_pub_.publish(out);
    }
    prev_gray_ = gray;
    prev_header_ = msg->header;
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "flow_baseline: %s: frame %.6f dropped: %s", image_sub_.getTopic().c_str(),
                       msg->header.stamp.toSec(), e.what());
  }
}

}  // namespace viper
