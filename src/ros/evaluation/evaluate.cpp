#include "viper/ros/evaluation/evaluate.h"

#include "viper/ground_truth/ego_motion.h"
#include "viper/evaluation/eval_report.h"
#include "viper/evaluation/plots.h"
#include "viper/ros/ground_truth/instances.h"

#include <std_msgs/String.h>

#include <cstdlib>
#include <mutex>

namespace viper {
namespace {

// Draw lists remembered for conditions, frame numbers and the frame before a stamp.
constexpr size_t kFramesHeld = 2000;

std::string defaultReportDir() {
  if (const char* home = std::getenv("ROS_HOME")) return std::string(home) + "/viper_evaluation";
  if (const char* home = std::getenv("HOME")) return std::string(home) + "/.ros/viper_evaluation";
  return "viper_evaluation";
}

// Reads a "first"/"second" parameter: whether it says "second"; the default after an error.
bool secondParam(const ros::NodeHandle& pnh, const std::string& name, bool second_by_default) {
  std::string v;
  pnh.param<std::string>(name, v, second_by_default ? "second" : "first");
  if (v != "first" && v != "second") {
    ROS_ERROR("%s: ~%s must be 'first' or 'second' (got '%s'); using '%s'", pnh.getNamespace().c_str(), name.c_str(),
              v.c_str(), second_by_default ? "second" : "first");
    return second_by_default;
  }
  return v == "second";
}

// A flow prediction stamped with the second frame of its pair, which came before that frame's
// draw list, waits for it (at most `depth` of them).
template <typename Pending>
void holdUntilDrawList(std::map<ros::Time, Pending>& early, const ros::Time& stamp, const Pending& msg, size_t depth) {
  early[stamp] = msg;
  while (early.size() > depth) early.erase(early.begin());
}

}  // namespace

Evaluate::Evaluate(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), private_nh_(pnh) {}

Evaluate::AllMetricsLock Evaluate::lockAllMetrics() {
  return AllMetricsLock(semantic_mutex_, instance_mutex_, flow_mutex_, sparse_mutex_, pose_mutex_);
}

Evaluate::~Evaluate() {
  publish_timer_.stop();
  tf_timer_.stop();
  if (!evaluation_ || !write_on_shutdown_) return;
  std::string message;
  {
    const auto lock = lockAllMetrics();
    if (evaluation_->framesAdded() == 0 || evaluation_->framesAdded() == reported_at_frames_) return;
  }
  if (writeReport(message)) ROS_INFO("%s: report written on shutdown: %s", private_nh_.getNamespace().c_str(), message.c_str());
}

bool Evaluate::start() {
  const std::string me = private_nh_.getNamespace();
  std::optional<ClassTable> classes = loadClassTableParam(private_nh_);
  if (!classes) return false;

  EvaluationOptions options;
  private_nh_.param("min_instance_px", options.min_instance_px, 100);
  if (options.min_instance_px < 0) {
    ROS_ERROR("%s: ~min_instance_px must be >= 0 (got %d); using 100", me.c_str(), options.min_instance_px);
    options.min_instance_px = 100;
  }
  std::vector<double> lengths;
  if (private_nh_.getParam("odometry_segment_lengths_m", lengths)) {
    bool ok = !lengths.empty();
    for (double l : lengths) ok = ok && l > 0.0;
    if (!ok) {
      ROS_FATAL("%s: ~odometry_segment_lengths_m must be a non-empty list of positive lengths in metres, "
                "e.g. [100, 200, 300, 400, 500, 600, 700, 800]",
                me.c_str());
      return false;
    }
    options.odometry_lengths_m = lengths;
  }
  int step = 10;
  private_nh_.param("odometry_step_frames", step, 10);
  if (step < 1) {
    ROS_ERROR("%s: ~odometry_step_frames must be >= 1 (got %d); using 10", me.c_str(), step);
    step = 10;
  }
  options.odometry_step_frames = static_cast<size_t>(step);
  try {
    evaluation_ = std::make_unique<Evaluation>(*classes, options);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", me.c_str(), e.what());
    return false;
  }

  private_nh_.param<std::string>("report_dir", report_dir_, defaultReportDir());
  if (report_dir_.empty()) {
    ROS_FATAL("%s: ~report_dir is empty: give the folder the report is written to", me.c_str());
    return false;
  }
  private_nh_.param("write_on_shutdown", write_on_shutdown_, true);
  private_nh_.param<std::string>("condition", default_condition_, "unknown");
  if (default_condition_.empty()) default_condition_ = "unknown";
  double period_s = 1.0;
  private_nh_.param("publish_period_s", period_s, 1.0);
  if (!(period_s > 0.0)) {
    ROS_ERROR("%s: ~publish_period_s must be > 0 (got %g); using 1", me.c_str(), period_s);
    period_s = 1.0;
  }
  int queue_size = 10;
  private_nh_.param("queue_size", queue_size, 10);
  if (queue_size < 1) {
    ROS_ERROR("%s: ~queue_size must be >= 1 (got %d); using 10", me.c_str(), queue_size);
    queue_size = 10;
  }
  flow_stamp_second_ = secondParam(private_nh_, "flow_stamp", false);
  sparse_stamp_second_ = secondParam(private_nh_, "sparse_flow_stamp", true);
  sparse_points_ = secondParam(private_nh_, "sparse_flow_points", false) ? SparsePoints::kSecondFrame
                                                                         : SparsePoints::kFirstFrame;
  std::string estimate_frame;
  private_nh_.param<std::string>("odometry_estimate_frame", estimate_frame, "body");
  if (estimate_frame != "body" && estimate_frame != "optical") {
    ROS_ERROR("%s: ~odometry_estimate_frame must be 'body' (x forward, z up) or 'optical' (z forward, y down); "
              "got '%s', using 'body'",
              me.c_str(), estimate_frame.c_str());
    estimate_frame = "body";
  }
  estimate_optical_ = estimate_frame == "optical";
  private_nh_.param<std::string>("estimate_tf_parent", tf_parent_, "");
  private_nh_.param<std::string>("estimate_tf_child", tf_child_, "");
  if (tf_parent_.empty() != tf_child_.empty()) {
    ROS_FATAL("%s: give both ~estimate_tf_parent and ~estimate_tf_child (the estimate's tf frames), or neither "
              "(then the estimate comes from the odom topic)",
              me.c_str());
    return false;
  }
  private_nh_.param("tf_wait_s", tf_wait_s_, 1.0);
  if (!(tf_wait_s_ > 0.0)) {
    ROS_ERROR("%s: ~tf_wait_s must be > 0 (got %g); using 1", me.c_str(), tf_wait_s_);
    tf_wait_s_ = 1.0;
  }
  private_nh_.param("shutdown_after_idle_s", idle_shutdown_s_, 0.0);
  if (idle_shutdown_s_ < 0.0) {
    ROS_ERROR("%s: ~shutdown_after_idle_s must be >= 0 (got %g); using 0 (never)", me.c_str(), idle_shutdown_s_);
    idle_shutdown_s_ = 0.0;
  }

  depth_ = static_cast<size_t>(queue_size);
  semantic_join_ = StampJoin<SemanticEntry>(depth_);
  instance_join_ = StampJoin<InstanceEntry>(depth_);
  flow_join_ = StampJoin<FlowEntry>(depth_);
  sparse_join_ = StampJoin<SparseEntry>(depth_);
  pose_join_ = StampJoin<PoseEntry>(depth_);

  scores_pub_ = private_nh_.advertise<std_msgs::String>("scores", 1, true);
  report_srv_ = private_nh_.advertiseService("write_report", &Evaluate::onWriteReport, this);
  const uint32_t q = static_cast<uint32_t>(queue_size);
  draws_sub_ = nh_.subscribe("capture/draws", 2 * q, &Evaluate::onDraws, this);
  gt_semantic_sub_ = nh_.subscribe("ground_truth/semantic", q, &Evaluate::onGtSemantic, this);
  gt_ids_sub_ = nh_.subscribe("ground_truth/instance_ids", q, &Evaluate::onGtInstanceIds, this);
  gt_flow_sub_ = nh_.subscribe("ground_truth/flow/forward", q, &Evaluate::onGtFlow, this);
  gt_visible_sub_ = nh_.subscribe("ground_truth/flow/forward_visible", q, &Evaluate::onGtFlowVisible, this);
  gt_odom_sub_ = nh_.subscribe("ground_truth/odom", 2 * q, &Evaluate::onGtOdom, this);
  semantic_sub_ = nh_.subscribe("semantic", q, &Evaluate::onSemantic, this);
  instances_sub_ = nh_.subscribe("instances", q, &Evaluate::onInstances, this);
  flow_sub_ = nh_.subscribe("flow", q, &Evaluate::onFlow, this);
  sparse_sub_ = nh_.subscribe("flow_sparse", q, &Evaluate::onFlowSparse, this);
  if (tf_parent_.empty()) {
    odom_sub_ = nh_.subscribe("odom", 2 * q, &Evaluate::onOdom, this);
  } else {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(30.0));
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
    tf_timer_ = nh_.createSteadyTimer(ros::WallDuration(0.02), &Evaluate::onTfPoll, this);
  }
  publish_timer_ = nh_.createSteadyTimer(ros::WallDuration(period_s), &Evaluate::onPublishTimer, this);
  const std::string poses = tf_parent_.empty() ? odom_sub_.getTopic() : "tf " + tf_parent_ + " -> " + tf_child_;
  ROS_INFO("%s: scoring %s, %s, %s, %s and %s against the ground truth; report into %s", me.c_str(),
           semantic_sub_.getTopic().c_str(), instances_sub_.getTopic().c_str(), flow_sub_.getTopic().c_str(),
           sparse_sub_.getTopic().c_str(), poses.c_str(), report_dir_.c_str());
  return true;
}

void Evaluate::noteInput() {
  last_input_ = ros::SteadyTime::now();
  any_input_ = true;
}

// ---- ground truth --------------------------------------------------------------------------

bool Evaluate::drawsExpected() const { return draws_seen_ || draws_sub_.getNumPublishers() > 0; }

template <typename Entry, typename Set>
std::optional<Entry> Evaluate::put(StampJoin<Entry>& join, const ros::Time& stamp, Set&& set) {
  return join.put(stamp, [&](Entry& e) {
    set(e);
    if (e.frame) return;
    const auto it = frames_.find(stamp);
    if (it != frames_.end()) {
      e.frame = it->second;
    } else if (!drawsExpected()) {
      e.frame = FrameInfo{++frame_counter_, default_condition_};
    }
  });
}

void Evaluate::onDraws(const DrawList::ConstPtr& msg) {
  const ros::Time t = msg->header.stamp;
  std::optional<SemanticEntry> semantic;
  std::optional<InstanceEntry> instances;
  std::optional<FlowEntry> flow, early_flow;
  std::optional<SparseEntry> sparse, early_sparse;
  std::optional<PoseEntry> pose;
  ros::Time early_flow_t, early_sparse_t;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    draws_seen_ = true;
    const FrameInfo info{msg->frame_number, msg->condition.empty() ? default_condition_ : msg->condition};
    frames_[t] = info;
    while (frames_.size() > kFramesHeld) frames_.erase(frames_.begin());
    semantic = semantic_join_.update(t, [&](SemanticEntry& e) { e.frame = info; });
    instances = instance_join_.update(t, [&](InstanceEntry& e) { e.frame = info; });
    flow = flow_join_.update(t, [&](FlowEntry& e) { e.frame = info; });
    sparse = sparse_join_.update(t, [&](SparseEntry& e) { e.frame = info; });
    pose = pose_join_.update(t, [&](PoseEntry& e) { e.frame = info; });
    // Flow predictions stamped with this frame, which arrived before its draw list.
    if (const auto it = early_flow_.find(t); it != early_flow_.end()) {
      const ImagePtr pred = it->second;
      early_flow_.erase(it);
      if (const auto prev = previousFrame(t, flow_sub_.getTopic())) {
        early_flow_t = *prev;
        early_flow = put(flow_join_, *prev, [&](FlowEntry& e) { e.pred = pred; });
      }
    }
    if (const auto it = early_sparse_.find(t); it != early_sparse_.end()) {
      const auto pred = it->second;
      early_sparse_.erase(it);
      if (const auto prev = previousFrame(t, sparse_sub_.getTopic())) {
        early_sparse_t = *prev;
        early_sparse = put(sparse_join_, *prev, [&](SparseEntry& e) { e.pred = pred; });
      }
    }
  }
  if (semantic) score(t, *semantic);
  if (instances) score(t, *instances);
  if (flow) score(t, *flow);
  if (sparse) score(t, *sparse);
  if (pose) score(t, *pose);
  if (early_flow) score(early_flow_t, *early_flow);
  if (early_sparse) score(early_sparse_t, *early_sparse);
}

void Evaluate::onGtSemantic(const ImagePtr& msg) {
  std::optional<SemanticEntry> semantic;
  std::optional<InstanceEntry> instances;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    const ros::Time t = msg->header.stamp;
    // Ground truth waits only for predictions that someone publishes.
    if (semantic_sub_.getNumPublishers() > 0)
      semantic = put(semantic_join_, t, [&](SemanticEntry& e) { e.gt = msg; });
    if (instances_sub_.getNumPublishers() > 0)
      instances = put(instance_join_, t, [&](InstanceEntry& e) { e.gt_classes = msg; });
  }
  if (semantic) score(msg->header.stamp, *semantic);
  if (instances) score(msg->header.stamp, *instances);
}

void Evaluate::onGtInstanceIds(const ImagePtr& msg) {
  std::optional<InstanceEntry> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    if (instances_sub_.getNumPublishers() > 0)
      done = put(instance_join_, msg->header.stamp, [&](InstanceEntry& e) { e.gt_ids = msg; });
  }
  if (done) score(msg->header.stamp, *done);
}

void Evaluate::onGtFlow(const ImagePtr& msg) {
  std::optional<FlowEntry> dense;
  std::optional<SparseEntry> sparse;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    const ros::Time t = msg->header.stamp;
    if (flow_sub_.getNumPublishers() > 0) dense = put(flow_join_, t, [&](FlowEntry& e) { e.gt = msg; });
    if (sparse_sub_.getNumPublishers() > 0) sparse = put(sparse_join_, t, [&](SparseEntry& e) { e.gt = msg; });
  }
  if (dense) score(msg->header.stamp, *dense);
  if (sparse) score(msg->header.stamp, *sparse);
}

void Evaluate::onGtFlowVisible(const ImagePtr& msg) {
  std::optional<FlowEntry> dense;
  std::optional<SparseEntry> sparse;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    const ros::Time t = msg->header.stamp;
    if (flow_sub_.getNumPublishers() > 0) dense = put(flow_join_, t, [&](FlowEntry& e) { e.visible = msg; });
    if (sparse_sub_.getNumPublishers() > 0)
      sparse = put(sparse_join_, t, [&](SparseEntry& e) { e.visible = msg; });
  }
  if (dense) score(msg->header.stamp, *dense);
  if (sparse) score(msg->header.stamp, *sparse);
}

void Evaluate::onGtOdom(const nav_msgs::Odometry::ConstPtr& msg) {
  Eigen::Isometry3d pose;
  const std::string problem = poseFromOdometry(*msg, pose);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", gt_odom_sub_.getTopic().c_str(),
                       msg->header.stamp.toSec(), problem.c_str());
    return;
  }
  std::optional<PoseEntry> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    if (tf_buffer_) {
      tf_pending_[msg->header.stamp] = ros::SteadyTime::now();
      done = put(pose_join_, msg->header.stamp, [&](PoseEntry& e) { e.gt = pose; });
    } else if (odom_sub_.getNumPublishers() > 0) {
      done = put(pose_join_, msg->header.stamp, [&](PoseEntry& e) { e.gt = pose; });
    }
  }
  if (done) score(msg->header.stamp, *done);
}

// ---- predictions ---------------------------------------------------------------------------

std::optional<ros::Time> Evaluate::previousFrame(const ros::Time& stamp, const std::string& topic) {
  const auto it = frames_.find(stamp);
  if (it == frames_.end() || it == frames_.begin()) return std::nullopt;  // the first frame: no pair ends here
  const auto prev = std::prev(it);
  if (prev->second.frame_number + 1 != it->second.frame_number) {
    ROS_WARN_THROTTLE(5, "%s: frame %lu (stamp %.6f) does not follow frame %lu: no ground-truth flow for that pair; "
                      "skipped",
                      topic.c_str(), static_cast<unsigned long>(it->second.frame_number), stamp.toSec(),
                      static_cast<unsigned long>(prev->second.frame_number));
    return std::nullopt;
  }
  return prev->first;
}

void Evaluate::onSemantic(const ImagePtr& msg) {
  std::optional<SemanticEntry> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    done = put(semantic_join_, msg->header.stamp, [&](SemanticEntry& e) { e.pred = msg; });
  }
  if (done) score(msg->header.stamp, *done);
}

void Evaluate::onInstances(const InstancePredictionArray::ConstPtr& msg) {
  std::optional<InstanceEntry> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    done = put(instance_join_, msg->header.stamp, [&](InstanceEntry& e) { e.pred = msg; });
  }
  if (done) score(msg->header.stamp, *done);
}

void Evaluate::onFlow(const ImagePtr& msg) {
  std::optional<FlowEntry> done;
  ros::Time t = msg->header.stamp;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    if (flow_stamp_second_) {
      if (!drawsExpected()) {
        ROS_WARN_THROTTLE(5, "%s: ~flow_stamp 'second' needs the draw lists (%s) to pair frames; skipped",
                          flow_sub_.getTopic().c_str(), draws_sub_.getTopic().c_str());
        return;
      }
      if (frames_.count(t) == 0) {
        holdUntilDrawList(early_flow_, t, msg, depth_);
        return;
      }
      const auto prev = previousFrame(t, flow_sub_.getTopic());
      if (!prev) return;
      t = *prev;
    }
    done = put(flow_join_, t, [&](FlowEntry& e) { e.pred = msg; });
  }
  if (done) score(t, *done);
}

void Evaluate::onFlowSparse(const opencv_apps::FlowArrayStamped::ConstPtr& msg) {
  std::optional<SparseEntry> done;
  ros::Time t = msg->header.stamp;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    if (sparse_stamp_second_) {
      if (!drawsExpected()) {
        ROS_WARN_THROTTLE(5, "%s: ~sparse_flow_stamp 'second' needs the draw lists (%s) to pair frames; skipped",
                          sparse_sub_.getTopic().c_str(), draws_sub_.getTopic().c_str());
        return;
      }
      if (frames_.count(t) == 0) {
        holdUntilDrawList(early_sparse_, t, msg, depth_);
        return;
      }
      const auto prev = previousFrame(t, sparse_sub_.getTopic());
      if (!prev) return;
      t = *prev;
    }
    done = put(sparse_join_, t, [&](SparseEntry& e) { e.pred = msg; });
  }
  if (done) score(t, *done);
}

void Evaluate::onOdom(const nav_msgs::Odometry::ConstPtr& msg) {
  Eigen::Isometry3d pose;
  const std::string problem = poseFromOdometry(*msg, pose);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; pose skipped", odom_sub_.getTopic().c_str(), msg->header.stamp.toSec(),
                       problem.c_str());
    return;
  }
  std::optional<PoseEntry> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    done = put(pose_join_, msg->header.stamp, [&](PoseEntry& e) { e.est = pose; });
  }
  if (done) score(msg->header.stamp, *done);
}

void Evaluate::onTfPoll(const ros::SteadyTimerEvent&) {
  std::vector<std::pair<ros::Time, PoseEntry>> done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    const ros::SteadyTime now = ros::SteadyTime::now();
    for (auto it = tf_pending_.begin(); it != tf_pending_.end();) {
      const ros::Time t = it->first;
      std::string error;
      if (tf_buffer_->canTransform(tf_parent_, tf_child_, t, &error)) {
        const geometry_msgs::TransformStamped m = tf_buffer_->lookupTransform(tf_parent_, tf_child_, t);
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        const auto& r = m.transform.rotation;
        pose.linear() = Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
        pose.translation() = Eigen::Vector3d(m.transform.translation.x, m.transform.translation.y,
                                             m.transform.translation.z);
        if (auto e = put(pose_join_, t, [&](PoseEntry& p) { p.est = pose; })) done.emplace_back(t, *e);
        it = tf_pending_.erase(it);
      } else if ((now - it->second).toSec() > tf_wait_s_) {
        ROS_WARN_THROTTLE(5, "%s: no tf %s -> %s at %.6f within %g s (%s); pose skipped",
                          private_nh_.getNamespace().c_str(), tf_parent_.c_str(), tf_child_.c_str(), t.toSec(),
                          tf_wait_s_, error.c_str());
        it = tf_pending_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const auto& [t, e] : done) score(t, e);
}

// ---- scoring -------------------------------------------------------------------------------

void Evaluate::score(const ros::Time& stamp, const SemanticEntry& e) {
  std::string problem = checkImage(*e.gt, "mono8");
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", gt_semantic_sub_.getTopic().c_str(), stamp.toSec(),
                       problem.c_str());
    return;
  }
  problem = checkImage(*e.pred, "mono8", e.gt->width, e.gt->height);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", semantic_sub_.getTopic().c_str(), stamp.toSec(),
                       problem.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(semantic_mutex_);
  evaluation_->addSemantic(e.frame->condition, e.gt->data.data(), e.pred->data.data(), e.gt->data.size());
}

void Evaluate::score(const ros::Time& stamp, const InstanceEntry& e) {
  std::string problem = checkImage(*e.gt_classes, "mono8");
  std::string topic = gt_semantic_sub_.getTopic();
  if (problem.empty()) {
    problem = checkImage(*e.gt_ids, "32SC1", e.gt_classes->width, e.gt_classes->height);
    topic = gt_ids_sub_.getTopic();
  }
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", topic.c_str(), stamp.toSec(), problem.c_str());
    return;
  }
  std::vector<BoxedInstance> predictions;
  problem = toBoxedInstances(*e.pred, e.gt_ids->width, e.gt_ids->height, predictions);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", instances_sub_.getTopic().c_str(), stamp.toSec(),
                       problem.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(instance_mutex_);
  try {
    evaluation_->addInstances(e.frame->condition, reinterpret_cast<const int32_t*>(e.gt_ids->data.data()),
                              e.gt_classes->data.data(), e.gt_ids->width, e.gt_ids->height, predictions);
  } catch (const std::exception& ex) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", instances_sub_.getTopic().c_str(), stamp.toSec(),
                       ex.what());
  }
}

void Evaluate::score(const ros::Time& stamp, const FlowEntry& e) {
  std::string problem = checkImage(*e.gt, "32FC2");
  std::string topic = gt_flow_sub_.getTopic();
  if (problem.empty()) {
    problem = checkImage(*e.visible, "mono8", e.gt->width, e.gt->height);
    topic = gt_visible_sub_.getTopic();
  }
  if (problem.empty()) {
    problem = checkImage(*e.pred, "32FC2", e.gt->width, e.gt->height);
    topic = flow_sub_.getTopic();
  }
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", topic.c_str(), stamp.toSec(), problem.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(flow_mutex_);
  evaluation_->addFlow(e.frame->condition, reinterpret_cast<const float*>(e.gt->data.data()), e.visible->data.data(),
                       reinterpret_cast<const float*>(e.pred->data.data()), e.visible->data.size());
}

void Evaluate::score(const ros::Time& stamp, const SparseEntry& e) {
  std::string problem = checkImage(*e.gt, "32FC2");
  std::string topic = gt_flow_sub_.getTopic();
  if (problem.empty()) {
    problem = checkImage(*e.visible, "mono8", e.gt->width, e.gt->height);
    topic = gt_visible_sub_.getTopic();
  }
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", topic.c_str(), stamp.toSec(), problem.c_str());
    return;
  }
  const std::vector<SparseFlowVector> vectors = fromFlowArray(*e.pred, sparse_points_);
  size_t scored = 0;
  {
    std::lock_guard<std::mutex> lock(sparse_mutex_);
    scored = evaluation_->addSparseFlow(e.frame->condition, reinterpret_cast<const float*>(e.gt->data.data()),
                                        e.visible->data.data(), e.gt->width, e.gt->height, vectors);
  }
  if (scored == 0 && !vectors.empty())
    ROS_WARN_THROTTLE(5, "%s (stamp %.6f): none of %zu flow vectors lies on a pixel of the %ux%u image with ground "
                      "truth (check ~sparse_flow_points)",
                      sparse_sub_.getTopic().c_str(), e.pred->header.stamp.toSec(), vectors.size(), e.gt->width,
                      e.gt->height);
}

void Evaluate::score(const ros::Time&, const PoseEntry& e) {
  // The estimate's child frame becomes the camera body frame (x forward, z up) of the ground truth.
  const Eigen::Isometry3d est = estimate_optical_ ? Eigen::Isometry3d(*e.est * bodyFromOptical().inverse()) : *e.est;
  std::lock_guard<std::mutex> lock(pose_mutex_);
  evaluation_->addPose(e.frame->condition, e.frame->frame_number, *e.gt, est);
}

// ---- scores and report ---------------------------------------------------------------------

std::string Evaluate::scores() {
  const auto lock = lockAllMetrics();
  return scoresYaml(evaluation_->summarize());
}

void Evaluate::onPublishTimer(const ros::SteadyTimerEvent&) {
  uint64_t frames = 0;
  {
    const auto lock = lockAllMetrics();
    frames = evaluation_->framesAdded();
  }
  if (frames != published_at_frames_) {
    std_msgs::String msg;
    msg.data = scores();
    scores_pub_.publish(msg);
    published_at_frames_ = frames;
  }
  bool idle = false;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    idle = idle_shutdown_s_ > 0.0 && any_input_ && (ros::SteadyTime::now() - last_input_).toSec() > idle_shutdown_s_;
  }
  if (idle && !shutdown_requested_) {
    shutdown_requested_ = true;
    std::string message;
    if (writeReport(message)) message = "report written: " + message;
    ROS_INFO("%s: no input for %g s: %s; shutting down", private_nh_.getNamespace().c_str(), idle_shutdown_s_,
             message.c_str());
    ros::requestShutdown();
  }
}

bool Evaluate::writeReport(std::string& message) {
  const auto lock = lockAllMetrics();
  const EvaluationSummary summary = evaluation_->summarize();
  std::vector<std::string> files;
  try {
    files = viper::writeReport(summary, report_dir_);
  } catch (const std::exception& e) {
    message = std::string("report not written: ") + e.what();
    ROS_ERROR("%s: %s", private_nh_.getNamespace().c_str(), message.c_str());
    return false;
  }
  reported_at_frames_ = evaluation_->framesAdded();
  std_msgs::String msg;
  msg.data = scoresYaml(summary);
  scores_pub_.publish(msg);
  message = report_dir_ + ":";
  for (const std::string& f : files) message += " " + f.substr(f.find_last_of('/') + 1);
  return true;
}

bool Evaluate::onWriteReport(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = writeReport(res.message);
  return true;
}

}  // namespace viper
