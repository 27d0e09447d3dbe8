#include "viper/ros/ground_truth/flow_node.h"
#include "viper/ros/ground_truth/mesh_store_input.h"
#include "viper/ros/node_params.h"

#include <algorithm>

namespace viper {

Flow::Flow(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), it_(nh), log_([this](StepInput input) { return topicOf(input); }) {}

bool Flow::start() {
  const std::string me = private_nh_.getNamespace();
  FlowSettings settings;
  private_nh_.param("wide_baseline", settings.wide_baseline, 0);
  if (settings.wide_baseline < 0) {
    ROS_ERROR("%s: ~wide_baseline must be >= 0 frames (got %d); using 0 (off)", me.c_str(), settings.wide_baseline);
    settings.wide_baseline = 0;
  }
  int window = 5;
  private_nh_.param("window_size", window, 5);
  if (window < 2 || window < settings.wide_baseline + 1) {
    const int fixed = std::max(std::max(2, settings.wide_baseline + 1), window);
    ROS_ERROR("%s: ~window_size must be >= 2 and >= ~wide_baseline + 1 (got %d, wide_baseline %d); using %d",
              me.c_str(), window, settings.wide_baseline, fixed);
    window = fixed;
  }
  settings.window_size = static_cast<size_t>(window);
  private_nh_.param("occlusion_relative", settings.options.occlusion_relative, settings.options.occlusion_relative);
  private_nh_.param("occlusion_absolute_m", settings.options.occlusion_absolute_m, settings.options.occlusion_absolute_m);
  if (!(settings.options.occlusion_relative >= 0.0 && settings.options.occlusion_relative < 1.0) ||
      !(settings.options.occlusion_absolute_m >= 0.0)) {
    ROS_ERROR("%s: ~occlusion_relative must be in [0, 1) and ~occlusion_absolute_m >= 0 (got %g, %g); using 0.005, "
              "0.02", me.c_str(), settings.options.occlusion_relative, settings.options.occlusion_absolute_m);
    settings.options = FlowOptions();
  }
  const int queue_size = queueSizeParam(private_nh_);

  forward_pub_ = it_.advertise("flow/forward", queue_size);
  forward_visible_pub_ = it_.advertise("flow/forward_visible", queue_size);
  backward_pub_ = it_.advertise("flow/backward", queue_size);
  backward_visible_pub_ = it_.advertise("flow/backward_visible", queue_size);
  scene_flow_pub_ = it_.advertise("flow/scene_flow", queue_size);
  if (settings.wide_baseline > 0) {
    wide_pub_ = it_.advertise("flow/wide", queue_size);
    wide_visible_pub_ = it_.advertise("flow/wide_visible", queue_size);
  }
  step_ = std::make_unique<FlowMessageStep>(settings);
  correspondences_srv_ = private_nh_.advertiseService("correspondences", &Flow::onCorrespondences, this);
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Flow::onMeshStore, this);
  const image_transport::TransportHints raw("raw");
  draws_sub_.subscribe(nh_, "draws", queue_size);
  depth_sub_.subscribe(it_, "depth", queue_size, raw);
  draw_ids_sub_.subscribe(it_, "draw_ids", queue_size, raw);
  primitive_ids_sub_.subscribe(it_, "primitive_ids", queue_size, raw);
  objects_sub_.subscribe(nh_, "objects", queue_size);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(
      SyncPolicy(queue_size), draws_sub_, depth_sub_, draw_ids_sub_, primitive_ids_sub_, objects_sub_);
  sync_->registerCallback(&Flow::onFrame, this);
  sync_->registerDropCallback(&Flow::onDrop, this);
  return true;
}

void Flow::onMeshStore(const MeshStore::ConstPtr& store) { addMeshStore(*store, step_, mutex_, cpu_, log_); }

std::string Flow::topicOf(StepInput input) const {
  switch (input) {
    case StepInput::kDraws: return draws_sub_.getTopic();
    case StepInput::kDrawIds: return draw_ids_sub_.getTopic();
    case StepInput::kDepth: return depth_sub_.getTopic();
    case StepInput::kPrimitiveIds: return primitive_ids_sub_.getTopic();
    case StepInput::kObjects: return objects_sub_.getTopic();
    case StepInput::kMeshStore: return mesh_store_sub_.getTopic();
    default: return defaultTopicOf(input);
  }
}

void Flow::onDrop(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
                  const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects) {
  // The synchroniser gave up on a stamp: name the topics that never delivered it.
  std::string missing, stamp;
  auto note = [&](const auto& msg, const std::string& topic) {
    if (msg) {
      if (stamp.empty()) stamp = std::to_string(msg->header.stamp.toSec());
    } else {
      missing += (missing.empty() ? "" : ", ") + topic;
    }
  };
  note(draws, draws_sub_.getTopic());
  note(depth, depth_sub_.getTopic());
  note(draw_ids, draw_ids_sub_.getTopic());
  note(primitive_ids, primitive_ids_sub_.getTopic());
  note(objects, objects_sub_.getTopic());
  const std::string what = objects ? "" : " (no object list: the draws of this frame have no association)";
  ROS_ERROR_THROTTLE(5, "frame at stamp %s dropped: no message on %s%s; no flow spans it", stamp.c_str(),
                     missing.c_str(), what.c_str());
}

void Flow::onFrame(const DrawList::ConstPtr& draws, const ImageConstPtr& depth, const ImageConstPtr& draw_ids,
                   const ImageConstPtr& primitive_ids, const ObjectArray::ConstPtr& objects) {
  const CpuMeter::Scope cpu(cpu_, true);
  FlowMessageStep::Want want;
  want.forward = forward_pub_.getNumSubscribers() > 0 || forward_visible_pub_.getNumSubscribers() > 0;
  want.backward = backward_pub_.getNumSubscribers() > 0 || backward_visible_pub_.getNumSubscribers() > 0;
  want.wide = wide_pub_.getNumSubscribers() > 0 || wide_visible_pub_.getNumSubscribers() > 0;
  want.scene_flow = scene_flow_pub_.getNumSubscribers() > 0;
  FlowMessageStep::Output out;
  StepProblems problems;
  bool kept = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    kept = step_->process(*draws, depth, draw_ids, primitive_ids, *objects, want, out, problems);
    cpu_.add(step_->helperCpuNs(), false);  // the backward flow's thread
  }
  log_.log(problems);
  if (!kept) return;
  if (out.forward.flow) forward_pub_.publish(out.forward.flow), forward_visible_pub_.publish(out.forward.visible);
  if (out.backward.flow) backward_pub_.publish(out.backward.flow), backward_visible_pub_.publish(out.backward.visible);
  if (out.wide.flow) wide_pub_.publish(out.wide.flow), wide_visible_pub_.publish(out.wide.visible);
  if (out.scene_flow) scene_flow_pub_.publish(out.scene_flow);
  ++frames_;
}

bool Flow::onCorrespondences(Correspondences::Request& req, Correspondences::Response& res) {
  StepProblems problems;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    step_->correspondences(req.stamp_a, req.stamp_b, res, problems);
  }
  log_.log(problems);
  return true;
}

}  // namespace viper
