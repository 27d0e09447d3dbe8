// Back-pressure for a player (bag_player, capture_bridge): with ~pace_topic set, the player sends a
// new frame only while fewer than ~max_in_flight of its frames are unfinished, a frame being finished
// once the pace topic (std_msgs/Header, e.g. output_counter's ~progress) has reported its stamp or a
// later one. So a replay at ~rate 0 runs exactly as fast as the pipeline takes, losing nothing.
// docs/capture_bridge.md#back-pressure.
#pragma once

#include <ros/ros.h>
#include <std_msgs/Header.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>

namespace viper {

/// What ~parameters configure.
struct PaceOptions {
  std::string topic;        ///< ~pace_topic: finished frames (std_msgs/Header stamps); empty: no back-pressure
  int max_in_flight = 2;    ///< ~max_in_flight: frames sent and not yet finished, at most
  double timeout_s = 10.0;  ///< ~pace_timeout_s: wait at most this long for room, then warn and send
};

/// Reads the options; returns an empty string or what is wrong.
std::string readPaceOptions(const ros::NodeHandle& pnh, PaceOptions& options);

/// Counts a player's unfinished frames and holds it back while there are too many.
class PaceGate {
 public:
  /// Subscribes to options.topic (resolved in `nh`) when it is set.
  PaceGate(ros::NodeHandle nh, const PaceOptions& options, std::string player);

  bool active() const { return !options_.topic.empty(); }
  /// Blocks until fewer than max_in_flight frames are unfinished, `stop` is set, or the timeout
  /// passes (then a throttled warning, and the frames in flight are given up on). Returns at once
  /// when not active. The result is false only when stopped.
  bool waitForRoom(const std::atomic<bool>& stop);
  /// A frame with this header stamp has been sent (again for each of its messages: counted once).
  void sent(const ros::Time& stamp);
  /// Frames sent and not yet finished.
  size_t inFlight() const;
  /// How often, and how long in all, the player waited.
  uint64_t waits() const { return waits_; }
  double waitedSeconds() const { return waited_s_; }

 private:
  void onFinished(const std_msgs::HeaderConstPtr& header);

  PaceOptions options_;
  std::string player_;
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::condition_variable room_;
  std::deque<ros::Time> in_flight_;  // stamps sent and not yet finished, oldest first
  ros::Time finished_;               // the latest finished stamp
  std::atomic<uint64_t> waits_{0};
  std::atomic<double> waited_s_{0.0};
};

}  // namespace viper
