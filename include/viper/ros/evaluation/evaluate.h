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

/// The evaluate node's class, shared by the node and the nodelet.
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
  // Each entry also waits for its frame's draw list (condition, frame number), which may arrive
  // after the images: topics are not ordered across connections.
  struct SemanticEntry {
    ImagePtr gt, pred;
    std::optional<FrameInfo> frame;
    bool complete() const { return gt && pred && frame; }
  };
  struct InstanceEntry {
    ImagePtr gt_classes, gt_ids;
    InstancePredictionArray::ConstPtr pred;
    std::optional<FrameInfo> frame;
    bool complete() const { return gt_classes && gt_ids && pred && frame; }
  };
  struct FlowEntry {
    ImagePtr gt, visible, pred;
    std::optional<FrameInfo> frame;
    bool complete() const { return gt && visible && pred && frame; }
  };
  struct SparseEntry {
    ImagePtr gt, visible;
    opencv_apps::FlowArrayStamped::ConstPtr pred;
    std::optional<FrameInfo> frame;
    bool complete() const { return gt && visible && pred && frame; }
  };
  struct PoseEntry {
    std::optional<Eigen::Isometry3d> gt, est;
    std::optional<FrameInfo> frame;
    bool complete() const { return gt && est && frame; }
  };

  // Ground truth.
  void onDraws(const DrawList::ConstPtr& msg);
  void onGtSemantic(const ImagePtr& msg);
  void onGtInstanceIds(const ImagePtr& msg);
  void onGtFlow(const ImagePtr& msg);
  void onGtFlowVisible(const ImagePtr& msg);
  void onGtOdom(const nav_msgs::Odometry::ConstPtr& msg);
  // Predictions.
  void onSemantic(const ImagePtr& msg);
  void onInstances(const InstancePredictionArray::ConstPtr& msg);
  void onFlow(const ImagePtr& msg);
  void onFlowSparse(const opencv_apps::FlowArrayStamped::ConstPtr& msg);
  void onOdom(const nav_msgs::Odometry::ConstPtr& msg);
  void onTfPoll(const ros::SteadyTimerEvent&);
  // Scoring of complete entries (ground truth stamp `stamp`).
  void score(const ros::Time& stamp, const SemanticEntry& e);
  void score(const ros::Time& stamp, const InstanceEntry& e);
  void score(const ros::Time& stamp, const FlowEntry& e);
  void score(const ros::Time& stamp, const SparseEntry& e);
  void score(const ros::Time& stamp, const PoseEntry& e);

  /// put() into `join` (join_mutex_ held), filling in the frame of `stamp` when its draw list is
  /// known, or the default condition when no draw lists are published.
  template <typename Entry, typename Set>
  std::optional<Entry> put(StampJoin<Entry>& join, const ros::Time& stamp, Set&& set);
  /// The stamp of the frame before `stamp` when the two are consecutive frames; nullopt (with a
  /// throttled warning naming `topic`) when unknown. join_mutex_ held; `stamp` must be in frames_.
  std::optional<ros::Time> previousFrame(const ros::Time& stamp, const std::string& topic);
  /// Whether draw lists come (one arrived, or someone publishes them). join_mutex_ held.
  bool drawsExpected() const;
  void noteInput();
  void onPublishTimer(const ros::SteadyTimerEvent&);
  bool onWriteReport(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  ros::NodeHandle nh_, private_nh_;
  std::unique_ptr<Evaluation> evaluation_;
  // evaluation_: one lock per metric, so that metrics are scored in parallel (nodelet threads);
  // summaries and reports take them all.
  std::mutex semantic_mutex_, instance_mutex_, flow_mutex_, sparse_mutex_, pose_mutex_;
  using AllMetricsLock = std::scoped_lock<std::mutex, std::mutex, std::mutex, std::mutex, std::mutex>;
  AllMetricsLock lockAllMetrics();
  std::mutex join_mutex_;   // the joins, frames_, counters
  std::string report_dir_, default_condition_;
  bool write_on_shutdown_ = true;
  bool flow_stamp_second_ = false, sparse_stamp_second_ = true;
  SparsePoints sparse_points_ = SparsePoints::kFirstFrame;
  bool estimate_optical_ = false;
  std::string tf_parent_, tf_child_;
  double tf_wait_s_ = 1.0;
  double idle_shutdown_s_ = 0.0;

  StampJoin<SemanticEntry> semantic_join_;
  StampJoin<InstanceEntry> instance_join_;
  StampJoin<FlowEntry> flow_join_;
  StampJoin<SparseEntry> sparse_join_;
  StampJoin<PoseEntry> pose_join_;
  std::map<ros::Time, FrameInfo> frames_;  // recent draw lists by stamp
  uint64_t frame_counter_ = 0;             // frame numbers when there are no draw lists
  bool draws_seen_ = false;
  // Flow predictions stamped with the second frame, waiting for that frame's draw list.
  std::map<ros::Time, ImagePtr> early_flow_;
  std::map<ros::Time, opencv_apps::FlowArrayStamped::ConstPtr> early_sparse_;
  size_t depth_ = 10;
  std::map<ros::Time, ros::SteadyTime> tf_pending_;  // ground-truth stamps waiting for the estimate's tf

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
