// output_counter nodelet: counts the ground-truth nodes' outputs inside their nodelet manager
// (zero-copy, so counting costs the pipeline nothing a real subscriber in the manager would not),
// for scripts/measure_pipeline.sh. Subscribes to every output of replay.launch's nodes (names
// relative to its namespace: run it in /ground_truth), and to the raw draw list and color image for
// reference. Once
// messages have arrived and none came for ~idle_s seconds, it writes ~report_file: one line per topic,
// "TOPIC COUNT FIRST_S LAST_S" (wall-clock seconds of the first and last message), and keeps running.
// With ~report_period_s > 0 it also writes the file every so many seconds while messages come (for
// scripts/soak_pipeline.sh, whose replay never goes idle).
// It also publishes ~progress (std_msgs/Header): the newest stamp that every output has reached
// (each has delivered that stamp or a later one; the flow outputs only with ~expect_flow, default
// true), the finished frames a player's back-pressure waits for (pace_gate.h, measure_pipeline.sh
// --throughput).
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
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
    bool expect_flow = true;
    pnh.param("expect_flow", expect_flow, true);
    if (report_file_.empty()) {
      NODELET_FATAL("output_counter: ~report_file is empty: give the file the counts are written to");
      return;
    }
    progress_pub_ = pnh.advertise<std_msgs::Header>("progress", 100);
    for (const char* t : {"semantic", "semantic_color", "instance_ids", "boundaries", "instances_viper", "semantic_overlay"})
      subscribe<sensor_msgs::Image>(t, true);
    for (const char* t : {"flow/forward", "flow/forward_visible", "flow/backward", "flow/backward_visible"})
      subscribe<sensor_msgs::Image>(t, expect_flow);
    subscribe<ObjectArray>("objects", true);
    subscribe<Box3DArray>("boxes", true);
    subscribe<Box3DArray>("boxes_optical", true);
    subscribe<nav_msgs::Odometry>("odom", true);
    subscribe<DrawList>("/capture/draws", false);
    // The overlay's other input: a source stopped mid-frame may have sent a frame's draws, not its color.
    subscribe<sensor_msgs::Image>("/capture/color/image_raw", false);
    timer_ = nh.createWallTimer(ros::WallDuration(0.5), [this](const ros::WallTimerEvent&) { maybeReport(); });
  }

  // Counts `topic`; an output (`paced`) also takes part in ~progress.
  template <typename M>
  void subscribe(const std::string& topic, bool paced) {
    if (paced) reached_[topic] = ros::Time();
    subs_.push_back(getNodeHandle().subscribe<M>(topic, 1000, [this, topic](const boost::shared_ptr<const M>& m) {
      count(topic, m->header.stamp);
    }));
  }

  void count(const std::string& topic, const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    Count& c = counts_[topic];
    c.last = ros::WallTime::now();
    if (c.n++ == 0) c.first = c.last;
    last_ = c.last;
    written_ = false;
    const auto it = reached_.find(topic);
    if (it == reached_.end() || stamp <= it->second) return;
    it->second = stamp;
    ros::Time all = stamp;  // the newest stamp every output has reached
    for (const auto& [t, reached] : reached_) all = std::min(all, reached);
    if (all <= progress_) return;
    progress_ = all;
    std_msgs::HeaderPtr h(new std_msgs::Header);
    h->stamp = all;
    progress_pub_.publish(h);
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
  std::map<std::string, ros::Time> reached_;  // per output, the newest stamp delivered
  ros::Time progress_;
  ros::Publisher progress_pub_;
  ros::WallTime last_;
  bool written_ = false;
  std::mutex mutex_;
  std::vector<ros::Subscriber> subs_;
  ros::WallTimer timer_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::OutputCounterNodelet, nodelet::Nodelet)
