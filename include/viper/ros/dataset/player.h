// player: publishes a folder in VIPER's release layout (any subset of img, cls, inst, flow, flowbw,
// bb, camera) on the topics and in the encodings of the ground-truth nodes, with /clock, a rate
// and looping. Topics and parameters: docs/viper_layout.md.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ros/dataset/viper_layout_conversions.h"

#include <image_transport/image_transport.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace viper {

/// Settings of the player, read from the private node handle (see loadPlayerOptions()).
struct PlayerOptions {
  std::string root;                    ///< ~root (required): the layout's root folder
  std::string split;                   ///< ~split: "" = the root's only split (else "train" if present)
  std::vector<std::string> sequences;  ///< ~sequence: "" = every sequence of the split; or "001,004"
  double fps = 15.0;                   ///< ~fps: frame rate of the sequences (VIPER's are ~15)
  double rate = 1.0;                   ///< ~rate: speed factor; 0 = as fast as possible
  bool loop = false;                   ///< ~loop: start over after the last sequence
  bool publish_clock = true;           ///< ~publish_clock: /clock from the frame stamps
  std::optional<double> start_time;    ///< ~start_time: stamp of the first frame (s); default 1 + frame/fps
  bool wait_for_subscribers = false;   ///< ~wait_for_subscribers: start once every topic with data is subscribed
  bool exit_when_done = false;         ///< ~exit_when_done: (node only) shut down after the last frame
  bool publish_tf = true;              ///< ~publish_tf: map -> body (per frame) and body -> optical (static)
  ViperTfFrames frames;                ///< ~map_frame, ~body_frame, ~frame_id (optical)
  std::set<dataset::ViperModality> modalities;  ///< ~modalities: e.g. "img,cls"; "" = all
  bool use_camera = true;              ///< whether ~modalities includes "camera" (or is empty)
  int queue_size = 10;                 ///< ~queue_size of every publisher
  int prefetch = 3;                    ///< ~prefetch: frames read ahead of publication (1..64)
};

/// Reads and validates the options once: impossible settings log ROS_FATAL with how to fix them and
/// return nullopt; wrong ones log an error and fall back to the default.
std::optional<PlayerOptions> loadPlayerOptions(const ros::NodeHandle& private_nh);

/// The player: publishers, a reading thread and a publishing thread. Used by the node and the nodelet.
class Player {
 public:
  /// Topics are advertised in `nh`'s namespace (`capture/...`, `ground_truth/...`); parameters come
  /// from `private_nh`.
  Player(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  ~Player();
  Player(const Player&) = delete;
  Player& operator=(const Player&) = delete;

  /// Validates the parameters, finds the sequences and starts playing. False (after ROS_FATAL)
  /// when the configuration is impossible (no root, no such split or sequence, nothing to play).
  /// `is_node`: whether the player may shut the process down (~exit_when_done).
  bool start(bool is_node);
  /// Stops both threads; idempotent.
  void stop();
  /// Frames published so far (over all passes).
  uint64_t framesPublished() const { return frames_published_; }
  /// Problems reported so far (bad or missing files, bad lines), over the first pass.
  uint64_t problemsReported() const { return problems_reported_; }
  /// Whether every pass that was asked for has been published.
  bool done() const { return done_; }

 private:
  struct Sequence {
    dataset::ViperSequenceFiles files;
    std::map<uint64_t, dataset::ViperCameraRow> camera;
    std::vector<uint64_t> frames;
  };
  struct Item {
    size_t pass = 0;  // problems are logged on pass 0 only
    size_t sequence = 0;
    bool first_of_sequence = false;
    bool end_of_pass = false;
    dataset::ViperFrame frame;
  };

  void readLoop();
  void publishLoop();
  bool nextItem(Item& item);
  void publishItem(const Item& item, const ros::Time& stamp);
  /// Logs a problem of pass `pass` (only the first pass's are logged and counted).
  void report(const std::string& problem, size_t pass);
  bool waitForSubscribers();
  bool sleepFor(double seconds);
  bool running() const;

  ros::NodeHandle nh_, private_nh_;
  PlayerOptions options_;
  bool is_node_ = true;
  std::optional<ClassTable> classes_;
  std::vector<Sequence> sequences_;
  std::vector<std::string> startup_problems_;  // found by start(), logged when playing begins
  std::unique_ptr<ViperMessageBuilder> builder_;

  image_transport::ImageTransport it_;
  image_transport::Publisher color_pub_, semantic_pub_, semantic_color_pub_, instance_ids_pub_, instances_viper_pub_,
      flow_forward_pub_, flow_backward_pub_;
  ros::Publisher camera_info_pub_, odom_pub_, path_pub_, boxes_pub_, boxes_optical_pub_, markers_pub_, clock_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_tf_;
  nav_msgs::Path path_;

  std::thread reader_, publisher_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  bool reader_finished_ = false;
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  std::atomic<uint64_t> frames_published_{0};
  std::atomic<uint64_t> problems_reported_{0};
};

}  // namespace viper
