#include "viper/ros/evaluation/evaluate.h"
#include "viper/ros/node_params.h"

#include "viper/evaluation/eval_report.h"
#include "viper/evaluation/plots.h"
#include "viper/ros/ground_truth/instances_node.h"

#include <std_msgs/String.h>

#include <cstdlib>
#include <mutex>

namespace viper {
namespace {

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

}  // namespace

Evaluate::Evaluate(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), private_nh_(pnh) {}

std::vector<std::unique_lock<std::mutex>> Evaluate::lockAllMetrics() {
  std::vector<std::unique_lock<std::mutex>> locks;
  for (const auto& slot : slots_) locks.emplace_back(slot->mutex);
  return locks;
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
  private_nh_.param("flow_fill_missing", options.flow_fill_missing, false);
  const std::string wauc = private_nh_.param<std::string>("flow_wauc", "integral");
  if (wauc == "sampled") {
    options.flow_wauc = WaucMode::kSampled;
  } else if (wauc != "integral") {
    ROS_ERROR("%s: ~flow_wauc must be integral or sampled (got '%s'); using integral", me.c_str(), wauc.c_str());
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
  const int queue_size = queueSizeParam(private_nh_);
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
  for (const auto& metric : evaluation_->metrics()) {
    slots_.push_back(std::make_unique<MetricSlot>());
    slots_.back()->metric = metric.get();
    slots_.back()->needs = metric->inputs();
    slots_.back()->join = StampJoin<FrameEntry>(depth_);
  }

  scores_pub_ = private_nh_.advertise<std_msgs::String>("scores", 1, true);
  report_srv_ = private_nh_.advertiseService("write_report", &Evaluate::onWriteReport, this);
  const uint32_t q = static_cast<uint32_t>(queue_size);
  draws_sub_ = nh_.subscribe("capture/draws", 2 * q, &Evaluate::onDraws, this);
  // An image topic: its message is `field` of the entries of the metrics that read `input`.
  const auto image = [&](const std::string& topic, MetricInput input, ImagePtr FrameEntry::*field) {
    const boost::function<void(const ImagePtr&)> callback = [this, input, field](const ImagePtr& msg) {
      deliverAndScore(msg->header.stamp, input, [&msg, field](FrameEntry& e) { e.*field = msg; });
    };
    return nh_.subscribe<sensor_msgs::Image>(topic, q, callback);
  };
  gt_semantic_sub_ = image("ground_truth/semantic", kGtSemantic, &FrameEntry::gt_semantic);
  gt_ids_sub_ = image("ground_truth/instance_ids", kGtInstanceIds, &FrameEntry::gt_ids);
  gt_flow_sub_ = image("ground_truth/flow/forward", kGtFlow, &FrameEntry::gt_flow);
  gt_visible_sub_ = image("ground_truth/flow/forward_visible", kGtFlow, &FrameEntry::gt_visible);
  gt_odom_sub_ = nh_.subscribe("ground_truth/odom", 2 * q, &Evaluate::onGtOdom, this);
  semantic_sub_ = image("semantic", kPredSemantic, &FrameEntry::pred_semantic);
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
