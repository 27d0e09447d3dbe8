// frame_counter nodelet: counts complete frames from capture_bridge inside the same nodelet manager
// (zero-copy): a frame counts when its color, depth, both camera infos, draw ids, primitive ids and
// draw list (one stamp) have all arrived. After ~frames complete frames it logs frames/s.
// The cross-process version is test/ros/bridge_throughput.cpp.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>

#include <map>
#include <mutex>

namespace viper {

/// Counts complete frames of the raw capture topics and reports the rate.
class FrameCounterNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    getPrivateNodeHandle().param("frames", frames_, 0);
    const uint32_t q = 100;
    subs_ = {nh.subscribe("color/image_raw", q, &FrameCounterNodelet::onImage, this),
             nh.subscribe("depth/image_raw", q, &FrameCounterNodelet::onImage, this),
             nh.subscribe("draw_ids", q, &FrameCounterNodelet::onImage, this),
             nh.subscribe("primitive_ids", q, &FrameCounterNodelet::onImage, this),
             nh.subscribe("color/camera_info", q, &FrameCounterNodelet::onInfo, this),
             nh.subscribe("depth/camera_info", q, &FrameCounterNodelet::onInfo, this),
             nh.subscribe("draws", q, &FrameCounterNodelet::onDraws, this)};
  }
  void onImage(const sensor_msgs::ImageConstPtr& m) { onHeader(m->header); }
  void onInfo(const sensor_msgs::CameraInfoConstPtr& m) { onHeader(m->header); }
  void onDraws(const DrawListConstPtr& m) { onHeader(m->header); }
  void onHeader(const std_msgs::Header& h) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (++parts_[h.stamp] < 7) return;
    parts_.erase(h.stamp);
    const ros::WallTime now = ros::WallTime::now();
    if (complete_++ == 0) first_ = now;
    if (complete_ > 1 && (complete_ == frames_ || complete_ % 100 == 0)) {
      NODELET_INFO("frame_counter: %d complete frames, %zu incomplete stamps, %.2f frames/s", complete_,
                   parts_.size(), (complete_ - 1) / (now - first_).toSec());
    }
  }

  int frames_ = 0, complete_ = 0;
  std::map<ros::Time, int> parts_;
  ros::WallTime first_;
  std::mutex mutex_;
  std::vector<ros::Subscriber> subs_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::FrameCounterNodelet, nodelet::Nodelet)
