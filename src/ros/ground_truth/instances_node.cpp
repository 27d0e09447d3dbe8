#include "viper/ros/ground_truth/instances_node.h"
#include "viper/ros/ground_truth/mesh_store_input.h"
#include "viper/ros/node_params.h"

#include <ros/package.h>

namespace viper {

std::optional<ClassTable> loadClassTableParam(const ros::NodeHandle& pnh) {
  std::string path;
  pnh.param<std::string>("class_table", path, ros::package::getPath("viper") + "/config/viper_classes.csv");
  try {
    return ClassTable::load(path);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: ~class_table: %s (set ~class_table to a CSV like config/viper_classes.csv)",
              pnh.getNamespace().c_str(), e.what());
    return std::nullopt;
  }
}

Instances::Instances(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), it_(nh), log_([this](StepInput input) { return topicOf(input); }) {}

bool Instances::start() {
  const std::string me = private_nh_.getNamespace();
  std::string label_path;
  if (!private_nh_.getParam("label_table", label_path) || label_path.empty()) {
    ROS_FATAL("%s: ~label_table is required: the resource label table (YAML) of the captured program, "
              "e.g. config/labels/world_labels.yaml", me.c_str());
    return false;
  }
  std::optional<ClassTable> classes = loadClassTableParam(private_nh_);
  if (!classes) return false;
  InstancesSettings settings;
  private_nh_.param("area_weighted_vote", settings.area_weighted_vote, settings.area_weighted_vote);
  private_nh_.param("extrapolate_frames", settings.extrapolate_frames, settings.extrapolate_frames);
  if (settings.extrapolate_frames < 0) {
    ROS_ERROR("%s: ~extrapolate_frames must be >= 0 (got %d); using 10", me.c_str(), settings.extrapolate_frames);
    settings.extrapolate_frames = 10;
  }
  private_nh_.param("lod_tolerance_m", settings.lod_tolerance_m, settings.lod_tolerance_m);
  private_nh_.param("resume_tracks_by_resources", settings.resume_tracks_by_resources,
                    settings.resume_tracks_by_resources);
  double alpha = 0.5;
  private_nh_.param("overlay_alpha", alpha, 0.5);
  if (!(alpha >= 0.0 && alpha <= 1.0)) {
    ROS_ERROR("%s: ~overlay_alpha must be in [0, 1] (got %g); using 0.5", me.c_str(), alpha);
    alpha = 0.5;
  }
  overlay_alpha_ = static_cast<float>(alpha);
  const int queue_size = queueSizeParam(private_nh_);
  try {
    step_ = std::make_unique<InstancesMessageStep>(LabelTable::load(label_path), std::move(*classes), settings);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: ~label_table: %s", me.c_str(), e.what());
    return false;
  }

  semantic_pub_ = it_.advertise("semantic", queue_size);
  semantic_color_pub_ = it_.advertise("semantic_color", queue_size);
  instance_ids_pub_ = it_.advertise("instance_ids", queue_size);
  boundaries_pub_ = it_.advertise("boundaries", queue_size);
  viper_pub_ = it_.advertise("instances_viper", queue_size);
  overlay_pub_ = it_.advertise("semantic_overlay", queue_size);
  color_sub_ = it_.subscribe("color", queue_size, &Instances::onColor, this);
  objects_pub_ = nh_.advertise<ObjectArray>("objects", queue_size);
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Instances::onMeshStore, this);
  draws_sub_.subscribe(nh_, "draws", queue_size);
  draw_ids_sub_.subscribe(nh_, "draw_ids", queue_size);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size), draws_sub_, draw_ids_sub_);
  sync_->registerCallback(&Instances::onFrame, this);
  return true;
}

std::string Instances::topicOf(StepInput input) const {
  switch (input) {
    case StepInput::kDraws: return draws_sub_.getTopic();
    case StepInput::kDrawIds: return draw_ids_sub_.getTopic();
    case StepInput::kMeshStore: return mesh_store_sub_.getTopic();
    case StepInput::kColor: return color_sub_.getTopic();
    default: return defaultTopicOf(input);
  }
}

void Instances::onMeshStore(const MeshStore::ConstPtr& store) { addMeshStore(*store, step_, mutex_, cpu_, log_); }

void Instances::onColor(const sensor_msgs::Image::ConstPtr& color) {
  const CpuMeter::Scope cpu(cpu_, false);
  std::lock_guard<std::mutex> lock(mutex_);
  if (overlay_pub_.getNumSubscribers() == 0) return;
  auto semantic = pending_semantic_.find(color->header.stamp);
  if (semantic != pending_semantic_.end()) {
    publishOverlay(*color, *semantic->second);
    pending_semantic_.erase(pending_semantic_.begin(), std::next(semantic));
    return;
  }
  pending_color_[color->header.stamp] = color;
  while (pending_color_.size() > 8) pending_color_.erase(pending_color_.begin());
}

void Instances::publishOverlay(const sensor_msgs::Image& color, const sensor_msgs::Image& semantic) {
  StepProblems problems;
  sensor_msgs::ImagePtr overlay = step_->overlay(color, semantic, overlay_alpha_, problems);
  log_.log(problems);
  if (overlay) overlay_pub_.publish(overlay);
}

void Instances::onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::Image::ConstPtr& ids) {
  const CpuMeter::Scope cpu(cpu_, true);
  std::lock_guard<std::mutex> lock(mutex_);
  InstanceImagesWanted want;
  want.semantic = semantic_pub_.getNumSubscribers() > 0;
  want.semantic_color = semantic_color_pub_.getNumSubscribers() > 0;
  want.instance_ids = instance_ids_pub_.getNumSubscribers() > 0;
  want.boundaries = boundaries_pub_.getNumSubscribers() > 0;
  want.instances_viper = viper_pub_.getNumSubscribers() > 0;
  InstancesMessageStep::Output out;
  StepProblems problems;
  const bool kept = step_->process(*draws, ids, want, out, problems);
  log_.log(problems);
  if (!kept) return;
  if (out.semantic) semantic_pub_.publish(out.semantic);
  if (out.semantic_color) semantic_color_pub_.publish(out.semantic_color);
  if (overlay_pub_.getNumSubscribers() > 0) {
    auto color = pending_color_.find(ids->header.stamp);
    if (color != pending_color_.end()) {
      publishOverlay(*color->second, *step_->lastSemantic());
      pending_color_.erase(pending_color_.begin(), std::next(color));
    } else {
      pending_semantic_[ids->header.stamp] = step_->lastSemantic();
      while (pending_semantic_.size() > 8) pending_semantic_.erase(pending_semantic_.begin());
    }
  }
  if (out.instance_ids) instance_ids_pub_.publish(out.instance_ids);
  if (out.boundaries) boundaries_pub_.publish(out.boundaries);
  if (out.instances_viper) viper_pub_.publish(out.instances_viper);
  objects_pub_.publish(out.objects);
  ++frames_;
}

}  // namespace viper
