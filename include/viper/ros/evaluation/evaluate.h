// evaluate: scores a user's perception topics against the ground truth, per condition and over
// all, publishes running scores and writes a report. Topics and parameters: docs/evaluate.md.
#pragma once

#include "viper/evaluation/evaluation.h"
#include "viper/ros/evaluation/evaluate_inputs.h"

#include <nav_msgs/Odometry.h>
#include <opencv_apps/FlowArrayStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <viper/DrawList.h>
#include <viper/InstancePredictionArray.h>

#include <Eigen/Geometry>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// Messages of several inputs gathered by stamp until every input has delivered (ExactTime
/// semantics); at most `depth` incomplete stamps are held, the oldest is dropped first.
template <typename Entry>
class StampJoin {
 public:
  explicit StampJoin(size_t depth = 10) : depth_(depth) {}
  /// Applies `set` to the entry of `stamp`; returns the entry (and forgets it) once complete.
  template <typename Set>
  std::optional<Entry> put(const ros::Time& stamp, Set&& set) {
    Entry& e = entries_[stamp];
    set(e);
    if (e.complete()) {
      Entry done = std::move(e);
      entries_.erase(stamp);
      return done;
    }
    while (entries_.size() > depth_) entries_.erase(entries_.begin()), ++dropped_;
    return std::nullopt;
  }
  /// As put(), but only if an entry of `stamp` exists already.
  template <typename Set>
  std::optional<Entry> update(const ros::Time& stamp, Set&& set) {
    if (entries_.count(stamp) == 0) return std::nullopt;
    return put(stamp, std::forward<Set>(set));
  }
  uint64_t dropped() const { return dropped_; }

 private:
  size_t depth_;
  std::map<ros::Time, Entry> entries_;
  uint64_t dropped_ = 0;
};

/// The evaluate node's class, shared by the node and the nodelet. It holds one join (by stamp), one
/// lock and one scoring path per registered metric (metric.h), fed by the topics of the inputs the
/// metric declares.
class Evaluate {
 public:
  Evaluate(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh);
  /// Writes the report if ~write_on_shutdown (default true) and something was scored.
  ~Evaluate();
  /// Reads and validates the parameters, subscribes and advertises. Returns false after a
  /// ROS_FATAL saying how to fix an impossible configuration.
  bool start();
  /// Writes the report into ~report_dir. Returns false with the reason in `message`; on success
  /// `message` lists the files.
  bool writeReport(std::string& message);
  /// The running scores (YAML), as published on ~scores.
  std::string scores();

 private:
  using ImagePtr = sensor_msgs::Image::ConstPtr;
  struct FrameInfo {
    uint64_t frame_number = 0;
    std::string condition;
  };
  // The messages of one frame that a metric reads (MetricInputs `needs`). An entry also waits for
  // its frame's draw list (condition, frame number), which may arrive after the images: topics
  // are not ordered across connections.
  struct FrameEntry {
    MetricInputs needs = 0;
    ImagePtr gt_semantic, gt_ids, gt_flow, gt_visible, pred_semantic, pred_flow;
    InstancePredictionArray::ConstPtr pred_instances;
    opencv_apps::FlowArrayStamped::ConstPtr pred_sparse;
    std::optional<Eigen::Isometry3d> gt_pose, pred_pose;
    std::optional<FrameInfo> frame;
    bool has(MetricInput input) const;
    bool complete() const;
  };
  using Setter = std::function<void(FrameEntry&)>;
  // One registered metric: its inputs, its join of them by stamp, and the lock of its scoring.
  struct MetricSlot {
    Metric* metric = nullptr;  // owned by evaluation_
    MetricInputs needs = 0;
    StampJoin<FrameEntry> join;
    std::mutex mutex;
  };
  using Completed = std::vector<std::pair<ros::Time, std::pair<MetricSlot*, FrameEntry>>>;

  // Ground truth and predictions: every topic hands its message to the joins of the metrics
  // that read it.
  void onDraws(const DrawList::ConstPtr& msg);
  void onGtOdom(const nav_msgs::Odometry::ConstPtr& msg);
  void onInstances(const InstancePredictionArray::ConstPtr& msg);
  void onFlow(const ImagePtr& msg);
  void onFlowSparse(const opencv_apps::FlowArrayStamped::ConstPtr& msg);
  void onOdom(const nav_msgs::Odometry::ConstPtr& msg);
  void onTfPoll(const ros::SteadyTimerEvent&);
  /// Puts one input of `stamp` into the join of every metric that reads it (ground truth only
  /// where the metric's predictions are published); completed entries go to `done`.
  /// join_mutex_ held.
  void deliver(const ros::Time& stamp, MetricInput input, const Setter& set, Completed& done);
  /// deliver() under join_mutex_, then scores what completed.
  void deliverAndScore(const ros::Time& stamp, MetricInput input, const Setter& set);
  /// A flow prediction: paired with the previous frame's ground truth when ~<stamp_param> is
  /// 'second' (held until its own frame's draw list is known), else with its own stamp's.
  void onPairPrediction(MetricInput input, const ros::Time& stamp, bool stamp_second, const std::string& stamp_param,
                        const Setter& set);
  /// Whether the predictions that `needs` names are published (a metric's ground truth waits
  /// only then).
  bool predictionsPublished(MetricInputs needs) const;
  /// The topic an input comes from (for messages).
  std::string topicOf(MetricInput input) const;
  /// Checks and converts a complete entry and adds it to its metric.
  void score(const ros::Time& stamp, MetricSlot& slot, const FrameEntry& e);
  void scoreAll(const Completed& done);
  /// Logs that a frame is skipped because of `problem` in `topic`, at most every 5 s per topic.
  void skipFrame(const std::string& topic, const ros::Time& stamp, const std::string& problem);
  /// Whether a message of `key` was logged less than 5 s ago (else notes that it is logged now).
  bool throttled(const std::string& key);

  /// put() into `join` (join_mutex_ held), filling in the frame of `stamp` when its draw list is
  /// known, or the default condition when no draw lists are published.
  std::optional<FrameEntry> put(MetricSlot& slot, const ros::Time& stamp, const Setter& set);
  /// The stamp of the frame before `stamp` when the two are consecutive frames; nullopt (with a
  /// throttled warning naming `topic`) when unknown. join_mutex_ held; `stamp` must be in frames_.
  std::optional<ros::Time> previousFrame(const ros::Time& stamp, const std::string& topic);
  /// Whether draw lists come (one arrived, or someone publishes them). join_mutex_ held.
  bool drawsExpected() const;
  void noteInput();
  void onPublishTimer(const ros::SteadyTimerEvent&);
  bool onWriteReport(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  /// Every metric's lock, taken in one order: for summaries and reports.
  std::vector<std::unique_lock<std::mutex>> lockAllMetrics();

  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<Evaluation> evaluation_;
  // One slot per metric, so that metrics are scored in parallel (nodelet threads).
  std::vector<std::unique_ptr<MetricSlot>> slots_;
  std::mutex join_mutex_;  // the joins, frames_, early_, counters
  std::string report_dir_, default_condition_;
  bool write_on_shutdown_ = true;
  bool flow_stamp_second_ = false, sparse_stamp_second_ = true;
  SparsePoints sparse_points_ = SparsePoints::kFirstFrame;
  bool estimate_optical_ = false;
  std::string tf_parent_, tf_child_;
  double tf_wait_s_ = 1.0;
  double idle_shutdown_s_ = 0.0;

  std::map<ros::Time, FrameInfo> frames_;  // recent draw lists by stamp
  uint64_t frame_counter_ = 0;             // frame numbers when there are no draw lists
  bool draws_seen_ = false;
  // Flow predictions stamped with the second frame, waiting for that frame's draw list.
  std::map<MetricInput, std::map<ros::Time, Setter>> early_;
  size_t depth_ = 10;
  std::map<ros::Time, ros::SteadyTime> tf_pending_;  // ground-truth stamps waiting for the estimate's tf
  std::mutex throttle_mutex_;                          // last_logged_
  std::map<std::string, ros::WallTime> last_logged_;  // by message key, for throttled()

  ros::Subscriber draws_sub_, gt_semantic_sub_, gt_ids_sub_, gt_flow_sub_, gt_visible_sub_, gt_odom_sub_;
  ros::Subscriber semantic_sub_, instances_sub_, flow_sub_, sparse_sub_, odom_sub_;
  ros::Publisher scores_pub_;
  ros::ServiceServer report_srv_;
  ros::SteadyTimer publish_timer_, tf_timer_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  uint64_t published_at_frames_ = 0, reported_at_frames_ = 0;
  ros::SteadyTime last_input_;
  bool any_input_ = false, shutdown_requested_ = false;
};

}  // namespace viper
