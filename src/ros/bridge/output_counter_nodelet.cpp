// output_counter nodelet: counts the ground-truth nodes' outputs inside their nodelet manager
// (zero-copy, so counting costs the pipeline nothing a real subscriber in the manager would not),
// for scripts/measure_pipeline.sh. Subscribes to every output of replay.launch's nodes (names
// relative to its namespace: run it in /ground_truth), and to the raw draw list and color image for
// reference. Once
// messages have arrived and none came for ~idle_s seconds, it writes ~report_file: one line per topic,
// "TOPIC COUNT FIRST_S LAST_S" (wall-clock seconds of the first and last message), and keeps running.
// With ~report_period_s > 0 it also writes the file every so many seconds while messages come (for
// scripts/soak_pipeline.sh, whose replay never goes idle).
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>

namespace viper {

/// Counts messages per output topic and writes the counts once the input has stopped.
class OutputCounterNodelet : public nodelet::Nodelet {
 private:
  struct Count {
    uint64_t n = 0;
    ros::WallTime first, last;
  };

  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    pnh.param<std::string>("report_file", report_file_, "");
    pnh.param("idle_s", idle_s_, 5.0);
    pnh.param("report_period_s", period_s_, 0.0);
    if (report_file_.empty()) {
      NODELET_FATAL("output_counter: ~report_file is empty: give the file the counts are written to");
      return;
    }
    const uint32_t q = 1000;
    for (const char* t : {"semantic", "semantic_color", "instance_ids", "boundaries", "instances_viper", "semantic_overlay",
                          "flow/forward", "flow/forward_visible", "flow/backward", "flow/backward_visible"})
      subs_.push_back(nh.subscribe<sensor_msgs::Image>(t, q, [this, t](const sensor_msgs::ImageConstPtr&) { count(t); }));
    subs_.push_back(nh.subscribe<ObjectArray>("objects", q, [this](const ObjectArray::ConstPtr&) { count("objects"); }));
    subs_.push_back(nh.subscribe<Box3DArray>("boxes", q, [this](const Box3DArray::ConstPtr&) { count("boxes"); }));
    subs_.push_back(nh.subscribe<Box3DArray>("boxes_optical", q, [this](const Box3DArray::ConstPtr&) { count("boxes_optical"); }));
    subs_.push_back(nh.subscribe<nav_msgs::Odometry>("odom", q, [this](const nav_msgs::OdometryConstPtr&) { count("odom"); }));
    subs_.push_back(nh.subscribe<DrawList>("/capture/draws", q, [this](const DrawList::ConstPtr&) { count("/capture/draws"); }));
    // The overlay's other input: a source stopped mid-frame may have sent a frame's draws, not its color.
    subs_.push_back(nh.subscribe<sensor_msgs::Image>("/capture/color/image_raw", q, [this](const sensor_msgs::ImageConstPtr&) {
      count("/capture/color/image_raw");
    }));
    timer_ = nh.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) { maybeReport(); });
  }

  void count(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    Count& c = counts_[topic];
    c.last = ros::WallTime::now();
    if (c.n++ == 0) c.first = c.last;
    last_ = c.last;
    written_ = false;
  }

  void maybeReport() {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::WallTime now = ros::WallTime::now();
    const bool periodic = period_s_ > 0 && !counts_.empty() && (now - reported_).toSec() >= period_s_;
    if (!periodic && (counts_.empty() || written_ || (now - last_).toSec() < idle_s_)) return;
    reported_ = now;
    // Written beside and renamed: a reader never sees half a report.
    const std::string partial = report_file_ + ".partial";
    std::ofstream out(partial);
    for (const auto& [topic, c] : counts_)
      out << topic << ' ' << c.n << ' ' << std::fixed << c.first.toSec() << ' ' << c.last.toSec() << '\n';
    out.close();
    if (!out || std::rename(partial.c_str(), report_file_.c_str()) != 0) {
      NODELET_ERROR("output_counter: cannot write '%s'", report_file_.c_str());
      return;
    }
    if (periodic) return;
    written_ = true;
    NODELET_INFO("output_counter: counts written to '%s'", report_file_.c_str());
  }

  std::string report_file_;
  double idle_s_ = 5.0, period_s_ = 0.0;
  ros::WallTime reported_;
  std::map<std::string, Count> counts_;
  ros::WallTime last_;
  bool written_ = false;
  std::mutex mutex_;
  std::vector<ros::Subscriber> subs_;
  ros::WallTimer timer_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::OutputCounterNodelet, nodelet::Nodelet)
