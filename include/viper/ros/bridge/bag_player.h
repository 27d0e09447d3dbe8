// bag_player: plays a raw bag inside a nodelet manager, zero-copy, the way capture_bridge plays a
// capture: every message is published as a typed shared message (sensor_msgs/Image, CameraInfo,
// viper/DrawList, viper/MeshStore; other types as they are), so subscribers in the same manager get
// it without serialisation. rosbag play, a process of its own, has to push every image through a
// socket (460 MB/s for 1080p raw topics at 15 Hz). docs/capture_bridge.md#bag_player.
#pragma once

#include "viper/dataset/bag_file_reader.h"
#include "viper/ros/conversions/image_msg_pool.h"
#include "viper/ros/measurement/cpu_meter.h"
#include "viper/ros/pacing/pace_gate.h"

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <thread>

namespace viper {

namespace dataset {
struct BagMessage;
}

/// What ~parameters configure.
struct BagPlayerOptions {
  std::string bag;             ///< ~bag: the bag to play (required)
  double rate = 1.0;           ///< ~rate: speed factor of the bag's times; 0 = as fast as possible
  double start_delay_s = 0.0;  ///< ~start_delay_s: wait after advertising, before the first message
  bool publish_clock = true;   ///< ~publish_clock: publish /clock from the bag's times
  int queue_size = 100;        ///< ~queue_size: outgoing queue per topic
  bool exit_when_done = false; ///< ~exit_when_done: (node only) shut down after the last message
  bool loop = false;           ///< ~loop: start over at the end, times, header and tf stamps continuing
  PaceOptions pace;            ///< ~pace_topic, ~max_in_flight, ~pace_timeout_s: back-pressure (pace_gate.h)
};

/// Reads the options from private parameters; returns an empty string or what is wrong.
std::string readBagPlayerOptions(const ros::NodeHandle& pnh, BagPlayerOptions& options);

/// Plays one bag on its own thread, paced by the bag's times.
class BagPlayer {
 public:
  BagPlayer(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~BagPlayer();

  /// Reads the parameters, opens the bag, advertises its topics and starts playing. False (with a
  /// fatal message naming the problem) when it cannot start.
  bool start(bool is_node);
  void stop();
  uint64_t messagesPublished() const { return published_; }

 private:
  // Where the play is: messages published, the first and last (shifted) bag time, when it began.
  struct Progress {
    uint64_t count = 0;
    ros::Time first, last;
    ros::WallTime wall_start;
  };
  // The times one pass covered (bag times, or header stamps): first, last, how many rises.
  struct Span {
    ros::Time first, last;
    uint64_t values = 0;
    void add(const ros::Time& t);  // zero (no stamp) is left out
    double step() const;           // the span plus its mean step (0.1 s with one value)
  };
  struct PassSpan {
    Span times, stamps;
    /// How much later the next pass must start: so that both bag times and stamps keep rising.
    ros::Duration step() const { return ros::Duration(std::max(times.step(), stamps.values ? stamps.step() : 0.0)); }
  };

  void run();
  // Plays the bag once, every time and header stamp `shift` later; false when stopped or damaged.
  bool playPass(const ros::Duration& shift, Progress& progress, PassSpan& span);
  // Publishes m with its header stamp `shift` later (typed messages; others as they are); returns
  // the message's header stamp (unshifted), zero for types without one.
  ros::Time publish(const dataset::BagMessage& m, const ros::Duration& shift);
  ros::Time publishImage(ros::Publisher& pub, const dataset::BagMessage& m, const ros::Duration& shift);
  // tf2_msgs/TFMessage: every transform's stamp shifted; returns the latest (unshifted) stamp.
  ros::Time publishTf(ros::Publisher& pub, const dataset::BagMessage& m, const ros::Duration& shift);
  bool sleepUntil(const ros::WallTime& t);

  ros::NodeHandle nh_, pnh_;
  BagPlayerOptions options_;
  bool is_node_ = true;
  std::map<std::string, ros::Publisher> pubs_;  // by topic
  std::map<std::string, geometry_msgs::TransformStamped> tf_static_;  // by child frame, as last sent
  // The image messages, recycled (by topic), and where the reader decompresses an image's pixels
  // straight into its message: the messages it took, by their pixels, until next() gives them out
  // (one of a chunk that turns out damaged stays until the player stops).
  struct ImageSink : dataset::BagBulkSink {
    uint8_t* bulk(const dataset::BagConnection& connection, const uint8_t* prefix, uint32_t available,
                  uint32_t size, uint32_t& offset) override;
    std::map<std::string, ImageMsgPool> pools;
    std::map<const uint8_t*, sensor_msgs::ImagePtr> pending;
  } image_sink_;
  std::unique_ptr<PaceGate> gate_;
  CpuMeter cpu_{"bag_player", pnh_};  // its thread's CPU a frame (cpu_meter.h)
  ros::Publisher clock_pub_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> published_{0};
};

}  // namespace viper
