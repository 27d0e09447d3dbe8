// The evaluate node's inputs: every topic hands its message to the joins (by stamp) of the
// metrics that read it; a complete entry is checked, converted into an EvalFrame and scored.
#include "viper/ros/evaluation/evaluate.h"

#include "viper/ground_truth/ego_motion.h"

#include <mutex>

namespace viper {
namespace {

// Draw lists remembered for conditions, frame numbers and the frame before a stamp.
constexpr size_t kFramesHeld = 2000;

// Every input, in the order a complete entry's messages are checked (the first image checked
// gives the frame's size).
constexpr MetricInput kInputs[] = {kGtSemantic,   kGtInstanceIds, kGtFlow,        kGtPose, kPredSemantic,
                                   kPredInstances, kPredFlow,      kPredSparseFlow, kPredPose};

}  // namespace

bool Evaluate::FrameEntry::has(MetricInput input) const {
  switch (input) {
    case kGtSemantic: return gt_semantic != nullptr;
    case kGtInstanceIds: return gt_ids != nullptr;
    case kGtFlow: return gt_flow && gt_visible;
    case kGtPose: return gt_pose.has_value();
    case kPredSemantic: return pred_semantic != nullptr;
    case kPredInstances: return pred_instances != nullptr;
    case kPredFlow: return pred_flow != nullptr;
    case kPredSparseFlow: return pred_sparse != nullptr;
    case kPredPose: return pred_pose.has_value();
  }
  return false;
}

bool Evaluate::FrameEntry::complete() const {
  if (!frame) return false;
  for (MetricInput input : kInputs)
    if ((needs & input) && !has(input)) return false;
  return true;
}

void Evaluate::noteInput() {
  last_input_ = ros::SteadyTime::now();
  any_input_ = true;
}

bool Evaluate::drawsExpected() const { return draws_seen_ || draws_sub_.getNumPublishers() > 0; }

std::string Evaluate::topicOf(MetricInput input) const {
  switch (input) {
    case kGtSemantic: return gt_semantic_sub_.getTopic();
    case kGtInstanceIds: return gt_ids_sub_.getTopic();
    case kGtFlow: return gt_flow_sub_.getTopic();
    case kGtPose: return gt_odom_sub_.getTopic();
    case kPredSemantic: return semantic_sub_.getTopic();
    case kPredInstances: return instances_sub_.getTopic();
    case kPredFlow: return flow_sub_.getTopic();
    case kPredSparseFlow: return sparse_sub_.getTopic();
    case kPredPose: return tf_buffer_ ? "tf " + tf_parent_ + " -> " + tf_child_ : odom_sub_.getTopic();
  }
  return "";
}

bool Evaluate::predictionsPublished(MetricInputs needs) const {
  const std::pair<MetricInput, const ros::Subscriber*> topics[] = {{kPredSemantic, &semantic_sub_},
                                                                   {kPredInstances, &instances_sub_},
                                                                   {kPredFlow, &flow_sub_},
                                                                   {kPredSparseFlow, &sparse_sub_}};
  for (const auto& [input, sub] : topics)
    if ((needs & input) && sub->getNumPublishers() == 0) return false;
  // With tf, the estimate is looked up for every ground-truth pose.
  return !(needs & kPredPose) || tf_buffer_ || odom_sub_.getNumPublishers() > 0;
}

std::optional<Evaluate::FrameEntry> Evaluate::put(MetricSlot& slot, const ros::Time& stamp, const Setter& set) {
  return slot.join.put(stamp, [&](FrameEntry& e) {
    e.needs = slot.needs;
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

void Evaluate::deliver(const ros::Time& stamp, MetricInput input, const Setter& set, Completed& done) {
  // Ground truth waits only for predictions that someone publishes.
  const bool ground_truth = (input & kPredictionInputs) == 0;
  for (const auto& slot : slots_) {
    if (!(slot->needs & input) || (ground_truth && !predictionsPublished(slot->needs))) continue;
    if (auto e = put(*slot, stamp, set)) done.push_back({stamp, {slot.get(), std::move(*e)}});
  }
}

void Evaluate::deliverAndScore(const ros::Time& stamp, MetricInput input, const Setter& set) {
  Completed done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    deliver(stamp, input, set, done);
  }
  scoreAll(done);
}

void Evaluate::scoreAll(const Completed& done) {
  for (const auto& [stamp, entry] : done) score(stamp, *entry.first, entry.second);
}

void Evaluate::onDraws(const DrawList::ConstPtr& msg) {
  const ros::Time t = msg->header.stamp;
  Completed done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    draws_seen_ = true;
    const FrameInfo info{msg->frame_number, msg->condition.empty() ? default_condition_ : msg->condition};
    frames_[t] = info;
    while (frames_.size() > kFramesHeld) frames_.erase(frames_.begin());
    for (const auto& slot : slots_)
      if (auto e = slot->join.update(t, [&](FrameEntry& f) { f.frame = info; })) done.push_back({t, {slot.get(), *e}});
    // Flow predictions stamped with this frame, which arrived before its draw list.
    for (auto& [input, early] : early_) {
      const auto it = early.find(t);
      if (it == early.end()) continue;
      const Setter set = it->second;
      early.erase(it);
      if (const auto prev = previousFrame(t, topicOf(input))) deliver(*prev, input, set, done);
    }
  }
  scoreAll(done);
}

void Evaluate::onGtOdom(const nav_msgs::Odometry::ConstPtr& msg) {
  Eigen::Isometry3d pose;
  const std::string problem = poseFromOdometry(*msg, pose);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; frame skipped", gt_odom_sub_.getTopic().c_str(),
                       msg->header.stamp.toSec(), problem.c_str());
    return;
  }
  Completed done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    if (tf_buffer_) tf_pending_[msg->header.stamp] = ros::SteadyTime::now();
    deliver(msg->header.stamp, kGtPose, [&](FrameEntry& e) { e.gt_pose = pose; }, done);
  }
  scoreAll(done);
}

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

void Evaluate::onInstances(const InstancePredictionArray::ConstPtr& msg) {
  deliverAndScore(msg->header.stamp, kPredInstances, [&](FrameEntry& e) { e.pred_instances = msg; });
}

void Evaluate::onPairPrediction(MetricInput input, const ros::Time& stamp, bool stamp_second,
                                const std::string& stamp_param, const Setter& set) {
  Completed done;
  {
    std::lock_guard<std::mutex> lock(join_mutex_);
    noteInput();
    ros::Time t = stamp;
    if (stamp_second) {
      if (!drawsExpected()) {
        if (!throttled("stamp " + stamp_param))
          ROS_WARN("%s: ~%s 'second' needs the draw lists (%s) to pair frames; skipped", topicOf(input).c_str(),
                   stamp_param.c_str(), draws_sub_.getTopic().c_str());
        return;
      }
      if (frames_.count(t) == 0) {  // held until that frame's draw list comes (at most depth_)
        std::map<ros::Time, Setter>& early = early_[input];
        early[t] = set;
        while (early.size() > depth_) early.erase(early.begin());
        return;
      }
      const auto prev = previousFrame(t, topicOf(input));
      if (!prev) return;
      t = *prev;
    }
    deliver(t, input, set, done);
  }
  scoreAll(done);
}

void Evaluate::onFlow(const ImagePtr& msg) {
  onPairPrediction(kPredFlow, msg->header.stamp, flow_stamp_second_, "flow_stamp",
                   [msg](FrameEntry& e) { e.pred_flow = msg; });
}

void Evaluate::onFlowSparse(const opencv_apps::FlowArrayStamped::ConstPtr& msg) {
  onPairPrediction(kPredSparseFlow, msg->header.stamp, sparse_stamp_second_, "sparse_flow_stamp",
                   [msg](FrameEntry& e) { e.pred_sparse = msg; });
}

void Evaluate::onOdom(const nav_msgs::Odometry::ConstPtr& msg) {
  Eigen::Isometry3d pose;
  const std::string problem = poseFromOdometry(*msg, pose);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (stamp %.6f): %s; pose skipped", odom_sub_.getTopic().c_str(), msg->header.stamp.toSec(),
                       problem.c_str());
    return;
  }
  deliverAndScore(msg->header.stamp, kPredPose, [&](FrameEntry& e) { e.pred_pose = pose; });
}

void Evaluate::onTfPoll(const ros::SteadyTimerEvent&) {
  Completed done;
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
        deliver(t, kPredPose, [&](FrameEntry& e) { e.pred_pose = pose; }, done);
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
  scoreAll(done);
}

// ---- scoring -------------------------------------------------------------------------------

// Throttled per topic: one call site serves every metric, and a bad topic must not hide another.
bool Evaluate::throttled(const std::string& key) {
  std::lock_guard<std::mutex> lock(throttle_mutex_);
  const ros::WallTime now = ros::WallTime::now();
  const auto it = last_logged_.find(key);
  if (it != last_logged_.end() && (now - it->second).toSec() < 5.0) return true;
  last_logged_[key] = now;
  return false;
}

void Evaluate::skipFrame(const std::string& topic, const ros::Time& stamp, const std::string& problem) {
  if (!throttled("error " + topic))
    ROS_ERROR("%s (stamp %.6f): %s; frame skipped", topic.c_str(), stamp.toSec(), problem.c_str());
}

void Evaluate::score(const ros::Time& stamp, MetricSlot& slot, const FrameEntry& e) {
  EvalFrame f;
  f.condition = e.frame->condition;
  f.frame_number = e.frame->frame_number;
  // The images the metric reads, each checked; the first one gives the frame's size.
  const std::tuple<MetricInput, const ImagePtr*, const char*> images[] = {
      {kGtSemantic, &e.gt_semantic, "mono8"}, {kGtInstanceIds, &e.gt_ids, "32SC1"},
      {kGtFlow, &e.gt_flow, "32FC2"},         {kGtFlow, &e.gt_visible, "mono8"},
      {kPredSemantic, &e.pred_semantic, "mono8"}, {kPredFlow, &e.pred_flow, "32FC2"}};
  bool sized = false;
  for (const auto& [input, image, encoding] : images) {
    if (!(slot.needs & input)) continue;
    const std::string problem = checkImage(**image, encoding, f.width, f.height);
    if (!problem.empty()) {
      skipFrame(image == &e.gt_visible ? gt_visible_sub_.getTopic() : topicOf(input), stamp, problem);
      return;
    }
    if (!sized) f.width = (*image)->width, f.height = (*image)->height, sized = true;
  }
  f.gt_semantic = e.gt_semantic ? e.gt_semantic->data.data() : nullptr;
  f.gt_instance_ids = e.gt_ids ? reinterpret_cast<const int32_t*>(e.gt_ids->data.data()) : nullptr;
  f.gt_flow = e.gt_flow ? reinterpret_cast<const float*>(e.gt_flow->data.data()) : nullptr;
  f.gt_flow_visible = e.gt_visible ? e.gt_visible->data.data() : nullptr;
  f.pred_semantic = e.pred_semantic ? e.pred_semantic->data.data() : nullptr;
  f.pred_flow = e.pred_flow ? reinterpret_cast<const float*>(e.pred_flow->data.data()) : nullptr;
  std::vector<BoxedInstance> instances;
  if (slot.needs & kPredInstances) {
    const std::string problem = toBoxedInstances(*e.pred_instances, f.width, f.height, instances);
    if (!problem.empty()) {
      skipFrame(instances_sub_.getTopic(), stamp, problem);
      return;
    }
    f.pred_instances = &instances;
  }
  std::vector<SparseFlowVector> vectors;
  if (slot.needs & kPredSparseFlow) {
    vectors = fromFlowArray(*e.pred_sparse, sparse_points_);
    f.pred_sparse_flow = &vectors;
  }
  // The estimate's child frame becomes the camera body frame (x forward, z up) of the ground truth.
  Eigen::Isometry3d estimate;
  if (e.gt_pose) f.gt_pose = &*e.gt_pose;
  if (e.pred_pose) {
    estimate = estimate_optical_ ? Eigen::Isometry3d(*e.pred_pose * bodyFromOptical().inverse()) : *e.pred_pose;
    f.pred_pose = &estimate;
  }
  uint64_t scored = 0;
  try {
    std::lock_guard<std::mutex> lock(slot.mutex);
    scored = slot.metric->add(f);
  } catch (const std::exception& ex) {
    MetricInput prediction = kPredSemantic;
    for (MetricInput input : kInputs)
      if ((slot.needs & input & kPredictionInputs) != 0) prediction = input;
    skipFrame(topicOf(prediction), stamp, ex.what());
    return;
  }
  if ((slot.needs & kPredSparseFlow) && scored == 0 && !vectors.empty())
    ROS_WARN_THROTTLE(5, "%s (stamp %.6f): none of %zu flow vectors lies on a pixel of the %ux%u image with ground "
                      "truth (check ~sparse_flow_points)",
                      sparse_sub_.getTopic().c_str(), e.pred_sparse->header.stamp.toSec(), vectors.size(), f.width,
                      f.height);
}

}  // namespace viper
