#include "viper/ros/dataset/player.h"
#include "viper/ros/node_params.h"

#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/ground_truth/instances_node.h"
#include "viper/ros/pacing/replay_timing.h"

#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>

#include <algorithm>
#include <deque>
#include <functional>
#include <future>
#include <sstream>

namespace viper {
namespace {

using dataset::ViperModality;

// Problems logged one by one on the first pass; after that only counted.
constexpr uint64_t kLoggedProblems = 200;
constexpr double kPollS = 0.02;
constexpr double kExitDrainS = 1.0;
constexpr size_t kPathMaxPoses = 10000;

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace

std::optional<PlayerOptions> loadPlayerOptions(const ros::NodeHandle& pnh) {
  const std::string me = pnh.getNamespace();
  PlayerOptions o;
  if (!pnh.getParam("root", o.root) || o.root.empty()) {
    ROS_FATAL("%s: ~root is required: the folder of a VIPER layout (<root>/<split>/<modality>/<seq>/...)", me.c_str());
    return std::nullopt;
  }
  pnh.param<std::string>("split", o.split, "");
  std::string sequences, modalities;
  pnh.param<std::string>("sequence", sequences, "");
  o.sequences = splitList(sequences);
  pnh.param("fps", o.fps, 15.0);
  if (!(o.fps > 0) || o.fps > 1000) {
    ROS_ERROR("%s: ~fps must be in (0, 1000] (got %g); using 15", me.c_str(), o.fps);
    o.fps = 15.0;
  }
  pnh.param("rate", o.rate, 1.0);
  if (!(o.rate >= 0)) {
    ROS_ERROR("%s: ~rate must be >= 0 (got %g); using 1", me.c_str(), o.rate);
    o.rate = 1.0;
  }
  pnh.param("loop", o.loop, false);
  pnh.param("publish_clock", o.publish_clock, true);
  double start_time = 0;
  if (pnh.getParam("start_time", start_time)) {
    if (start_time > 0) o.start_time = start_time;
    else ROS_ERROR("%s: ~start_time must be > 0 (got %g); using the default", me.c_str(), start_time);
  }
  pnh.param("wait_for_subscribers", o.wait_for_subscribers, false);
  pnh.param("exit_when_done", o.exit_when_done, false);
  pnh.param("publish_tf", o.publish_tf, true);
  pnh.param<std::string>("map_frame", o.frames.map, "map");
  pnh.param<std::string>("body_frame", o.frames.body, "camera");
  pnh.param<std::string>("frame_id", o.frames.optical, "camera_optical");
  if (o.frames.map.empty() || o.frames.body.empty() || o.frames.optical.empty() || o.frames.map == o.frames.body ||
      o.frames.body == o.frames.optical || o.frames.map == o.frames.optical) {
    ROS_FATAL("%s: ~map_frame ('%s'), ~body_frame ('%s') and ~frame_id ('%s') must be non-empty and differ", me.c_str(),
              o.frames.map.c_str(), o.frames.body.c_str(), o.frames.optical.c_str());
    return std::nullopt;
  }
  pnh.param<std::string>("modalities", modalities, "");
  for (const std::string& m : splitList(modalities)) {
    if (m == "camera") continue;
    const auto modality = dataset::viperModalityFromName(m);
    if (!modality) {
      ROS_FATAL("%s: ~modalities: unknown modality '%s' (use img, cls, inst, flow, flowbw, bb, camera)", me.c_str(),
                m.c_str());
      return std::nullopt;
    }
    o.modalities.insert(*modality);
  }
  const auto listed = splitList(modalities);
  o.use_camera = listed.empty() || std::find(listed.begin(), listed.end(), "camera") != listed.end();
  if (listed.empty()) o.modalities.insert(dataset::allViperModalities().begin(), dataset::allViperModalities().end());
  o.queue_size = queueSizeParam(pnh);
  pnh.param("prefetch", o.prefetch, 3);
  if (o.prefetch < 1 || o.prefetch > 64) {
    ROS_ERROR("%s: ~prefetch must be 1..64 (got %d); using 3", me.c_str(), o.prefetch);
    o.prefetch = 3;
  }
  return o;
}

Player::Player(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
    : nh_(nh), private_nh_(private_nh), it_(nh) {}

Player::~Player() { stop(); }

bool Player::start(bool is_node) {
  is_node_ = is_node;
  auto options = loadPlayerOptions(private_nh_);
  if (!options) return false;
  options_ = *options;
  if (options_.exit_when_done && !is_node_) {
    ROS_WARN("player: ~exit_when_done is ignored in a nodelet (it would end the whole manager)");
    options_.exit_when_done = false;
  }
  classes_ = loadClassTableParam(private_nh_);
  if (!classes_) return false;

  std::vector<std::string> splits;
  try {
    splits = dataset::listViperSplits(options_.root);
  } catch (const std::exception& e) {
    ROS_FATAL("player: %s. Check ~root.", e.what());
    return false;
  }
  if (options_.split.empty()) {
    if (splits.size() == 1) options_.split = splits.front();
    else if (std::find(splits.begin(), splits.end(), "train") != splits.end()) options_.split = "train";
  }
  if (options_.split.empty() || std::find(splits.begin(), splits.end(), options_.split) == splits.end()) {
    std::string found;
    for (const auto& s : splits) found += " " + s;
    ROS_FATAL("player: %s has no split '%s' (splits:%s). Set ~split.", options_.root.c_str(), options_.split.c_str(),
              found.empty() ? " none" : found.c_str());
    return false;
  }
  const std::vector<std::string> available = dataset::listViperSequences(options_.root, options_.split);
  std::vector<std::string> wanted = options_.sequences.empty() ? available : options_.sequences;
  for (const std::string& seq : wanted) {
    if (std::find(available.begin(), available.end(), seq) == available.end()) {
      ROS_FATAL("player: %s/%s has no sequence '%s' (%zu sequences there). Check ~sequence.", options_.root.c_str(),
                options_.split.c_str(), seq.c_str(), available.size());
      return false;
    }
    Sequence s;
    s.files = dataset::scanViperSequence(options_.root, options_.split, seq);
    for (const std::string& p : s.files.problems) startup_problems_.push_back(p);
    if (options_.use_camera && !s.files.camera_csv.empty()) {
      std::vector<std::string> problems;
      try {
        s.camera = dataset::readViperCameraCsv(s.files.camera_csv, problems);
      } catch (const std::exception& e) {
        problems.push_back(std::string(e.what()) + "; sequence played without camera");
      }
      for (const std::string& p : problems) startup_problems_.push_back(p);
    }
    if (!options_.use_camera) s.files.camera_csv.clear();
    for (auto it = s.files.files.begin(); it != s.files.files.end();)
      it = options_.modalities.count(it->first) ? std::next(it) : s.files.files.erase(it);
    s.frames = dataset::viperSequenceFrames(s.files, s.camera);
    for (const std::string& p : dataset::describeMissingFrames(s.files, s.camera, s.frames))
      startup_problems_.push_back(p);
    if (s.frames.empty()) {
      ROS_WARN("player: sequence %s of %s/%s has no frames of the chosen modalities; skipped", seq.c_str(),
               options_.root.c_str(), options_.split.c_str());
      continue;
    }
    sequences_.push_back(std::move(s));
  }
  if (sequences_.empty()) {
    ROS_FATAL("player: nothing to play in %s/%s (check ~sequence and ~modalities)", options_.root.c_str(),
              options_.split.c_str());
    return false;
  }
  size_t frames = 0;
  for (const auto& s : sequences_) frames += s.frames.size();
  ROS_INFO("player: %zu sequence(s), %zu frames of %s/%s at %g fps, rate %g%s", sequences_.size(), frames,
           options_.root.c_str(), options_.split.c_str(), options_.fps, options_.rate, options_.loop ? ", looping" : "");

  builder_ = std::make_unique<ViperMessageBuilder>(options_.frames, &*classes_);
  const uint32_t q = static_cast<uint32_t>(options_.queue_size);
  color_pub_ = it_.advertise(viper_topics::kColor, q);
  camera_info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>(viper_topics::kCameraInfo, q);
  semantic_pub_ = it_.advertise(viper_topics::kSemantic, q);
  semantic_color_pub_ = it_.advertise(viper_topics::kSemanticColor, q);
  instance_ids_pub_ = it_.advertise(viper_topics::kInstanceIds, q);
  instances_viper_pub_ = it_.advertise(viper_topics::kInstancesViper, q);
  flow_forward_pub_ = it_.advertise(viper_topics::kFlowForward, q);
  flow_backward_pub_ = it_.advertise(viper_topics::kFlowBackward, q);
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>(viper_topics::kOdom, q);
  path_pub_ = nh_.advertise<nav_msgs::Path>(viper_topics::kPath, 1, /*latch=*/true);
  boxes_pub_ = nh_.advertise<Box3DArray>(viper_topics::kBoxes, q);
  boxes_optical_pub_ = nh_.advertise<Box3DArray>(viper_topics::kBoxesOptical, q);
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>(viper_topics::kBoxMarkers, q);
  if (options_.publish_clock) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", q);
  if (options_.publish_tf) {
    tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
  }
  path_.header.frame_id = options_.frames.map;

  stop_ = false;
  reader_ = std::thread(&Player::readLoop, this);
  publisher_ = std::thread(&Player::publishLoop, this);
  return true;
}

void Player::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (reader_.joinable()) reader_.join();
  if (publisher_.joinable()) publisher_.join();
}

bool Player::running() const { return !stop_ && ros::ok(); }

bool Player::sleepFor(double seconds) {
  if (seconds > 0.0) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return stop_.load(); });
  }
  return running();
}

void Player::report(const std::string& problem, size_t pass) {
  if (pass > 0) return;
  const uint64_t n = ++problems_reported_;
  if (n <= kLoggedProblems) ROS_ERROR("player: %s", problem.c_str());
  else ROS_ERROR_THROTTLE(5, "player: %lu problems so far; latest: %s", static_cast<unsigned long>(n), problem.c_str());
}

void Player::readLoop() {
  // Problems are logged once someone listens (a tester subscribes to /rosout before the topics).
  if (options_.wait_for_subscribers && !waitForSubscribers()) return;
  for (const std::string& p : startup_problems_) report(p, 0);
  size_t pass = 0;
  do {
    for (size_t s = 0; s < sequences_.size() && running(); ++s) {
      const Sequence& seq = sequences_[s];
      uint32_t width = 0, height = 0;  // the sequence's size, once a frame has shown it
      // Frames are decoded by `prefetch` workers at once (PNG and npz decoding is the cost) and
      // queued in order; their problems are logged in frame order.
      using Read = std::pair<dataset::ViperFrame, std::vector<std::string>>;
      std::deque<std::future<Read>> ahead;
      size_t next = 0;
      for (size_t i = 0; i < seq.frames.size() && running(); ++i) {
        while (next < seq.frames.size() && ahead.size() < static_cast<size_t>(options_.prefetch)) {
          ahead.push_back(std::async(std::launch::async, [this, &seq, frame = seq.frames[next], width, height] {
            Read r;
            r.first = dataset::readViperFrame(seq.files, frame, seq.camera, options_.modalities, r.second, width, height);
            return r;
          }));
          ++next;
        }
        Read read = ahead.front().get();
        ahead.pop_front();
        Item item;
        item.pass = pass;
        item.sequence = s;
        item.first_of_sequence = i == 0;
        item.frame = std::move(read.first);
        for (const std::string& p : read.second) report(p, pass);
        if (width == 0 && item.frame.width > 0) width = item.frame.width, height = item.frame.height;
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || queue_.size() < static_cast<size_t>(options_.prefetch); });
        if (stop_) {
          lock.unlock();
          for (auto& f : ahead) f.wait();  // the workers use `seq`
          return;
        }
        queue_.push_back(std::move(item));
        changed_.notify_all();
      }
      for (auto& f : ahead) f.wait();
    }
    if (!running()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      Item end;
      end.end_of_pass = true;
      queue_.push_back(std::move(end));
    }
    changed_.notify_all();
    ++pass;
  } while (options_.loop && running());
  std::lock_guard<std::mutex> lock(mutex_);
  reader_finished_ = true;
  changed_.notify_all();
}

bool Player::nextItem(Item& item) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return stop_ || !queue_.empty() || reader_finished_; });
  if (stop_ || queue_.empty()) return false;
  item = std::move(queue_.front());
  queue_.pop_front();
  changed_.notify_all();
  return true;
}

bool Player::waitForSubscribers() {
  // Every topic that some sequence has data for.
  std::vector<std::pair<std::string, std::function<uint32_t()>>> topics;
  auto has = [&](ViperModality m) {
    return std::any_of(sequences_.begin(), sequences_.end(), [&](const Sequence& s) { return s.files.has(m); });
  };
  const bool camera = std::any_of(sequences_.begin(), sequences_.end(), [](const Sequence& s) { return !s.camera.empty(); });
  if (has(ViperModality::kImg)) topics.emplace_back(color_pub_.getTopic(), [this] { return color_pub_.getNumSubscribers(); });
  if (camera) topics.emplace_back(camera_info_pub_.getTopic(), [this] { return camera_info_pub_.getNumSubscribers(); });
  if (has(ViperModality::kCls) || has(ViperModality::kInst))
    topics.emplace_back(semantic_pub_.getTopic(), [this] { return semantic_pub_.getNumSubscribers(); });
  if (has(ViperModality::kInst)) {
    topics.emplace_back(instance_ids_pub_.getTopic(), [this] { return instance_ids_pub_.getNumSubscribers(); });
    topics.emplace_back(instances_viper_pub_.getTopic(), [this] { return instances_viper_pub_.getNumSubscribers(); });
  }
  if (has(ViperModality::kFlow))
    topics.emplace_back(flow_forward_pub_.getTopic(), [this] { return flow_forward_pub_.getNumSubscribers(); });
  if (has(ViperModality::kFlowBw))
    topics.emplace_back(flow_backward_pub_.getTopic(), [this] { return flow_backward_pub_.getNumSubscribers(); });
  if (has(ViperModality::kBb))
    topics.emplace_back(boxes_optical_pub_.getTopic(), [this] { return boxes_optical_pub_.getNumSubscribers(); });
  if (has(ViperModality::kBb) && camera) topics.emplace_back(boxes_pub_.getTopic(), [this] { return boxes_pub_.getNumSubscribers(); });
  if (camera) topics.emplace_back(odom_pub_.getTopic(), [this] { return odom_pub_.getNumSubscribers(); });
  bool logged = false;
  while (running()) {
    std::string missing;
    for (const auto& [name, count] : topics)
      if (count() == 0) missing += " " + name;
    if (missing.empty()) return true;
    if (!logged) {
      ROS_INFO("player: waiting for subscribers on%s (~wait_for_subscribers)", missing.c_str());
      logged = true;
    }
    sleepFor(kPollS);
  }
  return false;
}

void Player::publishLoop() {
  ReplayTiming timing(options_.rate, options_.start_time);
  bool first = true;
  ros::WallTime wall_start;
  double base_s = 0.0, last_s = 0.0;  // capture time of the pass: sequences follow each other
  bool pass_started = false;
  Item item;
  while (running() && nextItem(item)) {
    if (item.end_of_pass) {
      timing.beginLoop();
      pass_started = false;
      continue;
    }
    const double frame_s = static_cast<double>(item.frame.frame) / options_.fps;
    if (item.first_of_sequence) {
      base_s = pass_started ? last_s + 1.0 / options_.fps - frame_s : 0.0;
      builder_->startSequence();
      path_.poses.clear();
    }
    pass_started = true;
    last_s = base_s + frame_s;
    const double stamp_s = timing.stampOf(last_s);
    if (first) {
      wall_start = ros::WallTime::now();
      first = false;
    } else if (!sleepFor(timing.dueAfterStart(stamp_s) - (ros::WallTime::now() - wall_start).toSec())) {
      return;
    }
    publishItem(item, ros::Time(stamp_s));
  }
  if (!running()) return;
  done_ = true;
  ROS_INFO("player: done: %lu frames published, %lu problems reported", static_cast<unsigned long>(frames_published_.load()),
           static_cast<unsigned long>(problems_reported_.load()));
  if (options_.exit_when_done) {
    sleepFor(kExitDrainS);
    ros::requestShutdown();
  }
}

void Player::publishItem(const Item& item, const ros::Time& stamp) {
  ViperTopicSelection want;
  want.color = color_pub_.getNumSubscribers() > 0;
  want.camera_info = camera_info_pub_.getNumSubscribers() > 0;
  want.semantic = semantic_pub_.getNumSubscribers() > 0;
  want.semantic_color = semantic_color_pub_.getNumSubscribers() > 0;
  want.instance_ids = instance_ids_pub_.getNumSubscribers() > 0;
  want.instances_viper = instances_viper_pub_.getNumSubscribers() > 0;
  want.flow_forward = flow_forward_pub_.getNumSubscribers() > 0;
  want.flow_backward = flow_backward_pub_.getNumSubscribers() > 0;
  want.odom = true;
  want.boxes = true;  // also feeds the markers
  want.boxes_optical = boxes_optical_pub_.getNumSubscribers() > 0;
  ViperFrameMessages m;
  try {
    m = builder_->build(item.frame, stamp, want);
  } catch (const std::exception& e) {
    report("frame " + std::to_string(item.frame.frame) + " of sequence " + sequences_[item.sequence].files.seq + ": " +
               e.what() + "; frame dropped",
           item.pass);
    return;
  }
  for (const std::string& p : m.problems) report("sequence " + sequences_[item.sequence].files.seq + ", " + p, item.pass);

  // The clock first, so sim-time subscribers see the frame's time when its messages arrive.
  if (options_.publish_clock) {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  if (tf_ && m.map_to_body) {
    tf_->sendTransform(*m.map_to_body);
    if (item.first_of_sequence || frames_published_ == 0) static_tf_->sendTransform(builder_->bodyToOptical(stamp));
  }
  if (m.color) color_pub_.publish(m.color);
  if (m.camera_info) camera_info_pub_.publish(m.camera_info);
  if (m.semantic) semantic_pub_.publish(m.semantic);
  if (m.semantic_color) semantic_color_pub_.publish(m.semantic_color);
  if (m.instance_ids) instance_ids_pub_.publish(m.instance_ids);
  if (m.instances_viper) instances_viper_pub_.publish(m.instances_viper);
  if (m.flow_forward) flow_forward_pub_.publish(m.flow_forward);
  if (m.flow_backward) flow_backward_pub_.publish(m.flow_backward);
  if (m.odom) {
    odom_pub_.publish(m.odom);
    geometry_msgs::PoseStamped ps;
    ps.header = m.odom->header;
    ps.pose = m.odom->pose.pose;
    path_.header.stamp = stamp;
    path_.poses.push_back(ps);
    if (path_.poses.size() > kPathMaxPoses) path_.poses.erase(path_.poses.begin());
    path_pub_.publish(path_);
  }
  if (m.boxes) {
    boxes_pub_.publish(m.boxes);
    if (markers_pub_.getNumSubscribers() > 0) markers_pub_.publish(boxMarkers(*m.boxes, *classes_));
  }
  if (m.boxes_optical) boxes_optical_pub_.publish(m.boxes_optical);
  ++frames_published_;
}

}  // namespace viper
