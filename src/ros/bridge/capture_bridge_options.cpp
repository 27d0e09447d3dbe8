#include "viper/ros/bridge/capture_bridge.h"

#include <cmath>

namespace viper {

std::optional<CaptureBridgeOptions> loadCaptureBridgeOptions(const ros::NodeHandle& pnh) {
  CaptureBridgeOptions o;
  const std::string ns = pnh.getNamespace();

  if (!pnh.getParam("file", o.file) || o.file.empty()) {
    ROS_FATAL("capture_bridge: parameter %s/file is required: set it to the path of a .vcap capture, e.g. "
              "`rosrun viper capture_bridge _file:=/tmp/scene.vcap` or `roslaunch viper capture_bridge.launch "
              "file:=/tmp/scene.vcap`",
              ns.c_str());
    return std::nullopt;
  }
  if (o.file.size() < 5 || o.file.compare(o.file.size() - 5, 5, ".vcap") != 0) {
    ROS_WARN("capture_bridge: %s/file '%s' does not end in .vcap; reading it as a capture anyway", ns.c_str(),
             o.file.c_str());
  }

  pnh.param("follow", o.follow, o.follow);
  pnh.param("loop", o.loop, o.loop);
  pnh.param("wait_for_subscribers", o.wait_for_subscribers, o.wait_for_subscribers);
  pnh.param("publish_clock", o.publish_clock, o.publish_clock);
  pnh.param("exit_when_done", o.exit_when_done, o.exit_when_done);

  pnh.param("start_delay_s", o.start_delay_s, o.start_delay_s);
  if (!std::isfinite(o.start_delay_s) || o.start_delay_s < 0.0) {
    ROS_ERROR("capture_bridge: %s/start_delay_s = %g is invalid (seconds >= 0); starting at once", ns.c_str(),
              o.start_delay_s);
    o.start_delay_s = 0.0;
  }

  pnh.param("rate", o.rate, o.rate);
  if (!std::isfinite(o.rate) || o.rate < 0.0) {
    ROS_ERROR("capture_bridge: %s/rate = %g is invalid (a factor >= 0; 1 = real time, 0 = as fast as possible); "
              "using 1.0",
              ns.c_str(), o.rate);
    o.rate = 1.0;
  } else if (o.rate > 100.0) {
    ROS_WARN("capture_bridge: %s/rate = %g replays more than 100x real time; use 0 for 'as fast as possible'",
             ns.c_str(), o.rate);
  }

  if (o.loop && o.follow) {
    ROS_ERROR("capture_bridge: %s/loop and %s/follow exclude each other (a followed file has no end to loop at); "
              "not looping",
              ns.c_str(), ns.c_str());
    o.loop = false;
  }

  if (pnh.hasParam("start_time")) {
    double start_time = 0.0;
    if (!pnh.getParam("start_time", start_time) || !std::isfinite(start_time) || start_time <= 0.0) {
      ROS_ERROR("capture_bridge: %s/start_time must be a number of seconds > 0; using the capture times as stamps",
                ns.c_str());
    } else {
      o.start_time = start_time;
    }
  }

  pnh.param("frame_id", o.frame_id, o.frame_id);
  if (o.frame_id.empty()) {
    ROS_ERROR("capture_bridge: %s/frame_id is empty; using 'camera_optical'", ns.c_str());
    o.frame_id = "camera_optical";
  } else if (o.frame_id.front() == '/') {
    ROS_WARN("capture_bridge: %s/frame_id '%s' starts with '/', which tf2 rejects", ns.c_str(), o.frame_id.c_str());
  }

  pnh.param("queue_size", o.queue_size, o.queue_size);
  if (o.queue_size < 1) {
    ROS_ERROR("capture_bridge: %s/queue_size = %d must be >= 1; using 10", ns.c_str(), o.queue_size);
    o.queue_size = 10;
  }

  const std::string pace_problem = readPaceOptions(pnh, o.pace);
  if (!pace_problem.empty()) {
    ROS_FATAL("capture_bridge: %s: %s", ns.c_str(), pace_problem.c_str());
    return std::nullopt;
  }

  bool use_sim_time = false;
  ros::param::get("/use_sim_time", use_sim_time);
  if (use_sim_time && !o.publish_clock) {
    ROS_WARN("capture_bridge: /use_sim_time is true but %s/publish_clock is false: unless another node publishes "
             "/clock, nodes using sim time will not advance",
             ns.c_str());
  }
  if (o.wait_for_subscribers && o.follow) {
    ROS_WARN("capture_bridge: waiting for subscribers while following a live capture lets the file run ahead");
  }
  return o;
}

}  // namespace viper
