#include "viper/ros/ground_truth/instances.h"

#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ground_truth/semantic_overlay.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <ros/package.h>

#include <cstring>

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
    : nh_(nh), private_nh_(pnh), it_(nh) {}

bool Instances::start() {
  const std::string me = private_nh_.getNamespace();
  std::string label_path;
  if (!private_nh_.getParam("label_table", label_path) || label_path.empty()) {
    ROS_FATAL("%s: ~label_table is required: the resource label table (YAML) of the captured program, "
              "e.g. config/labels/world_labels.yaml", me.c_str());
    return false;
  }
  classes_ = loadClassTableParam(private_nh_);
  if (!classes_) return false;
  InstancePipelineOptions options;
  options.thing_classes = classes_->instanceEvalMask();
  options.thing_classes.resize(256, false);
  private_nh_.param("area_weighted_vote", options.area_weighted_vote, true);
  options.compute_boxes = false;  // the boxes node makes them
  int extrapolate = 10;
  private_nh_.param("extrapolate_frames", extrapolate, 10);
  if (extrapolate < 0) {
    ROS_ERROR("%s: ~extrapolate_frames must be >= 0 (got %d); using 10", me.c_str(), extrapolate);
    extrapolate = 10;
  }
  options.tracker.extrapolate_frames = extrapolate;
  private_nh_.param("lod_tolerance_m", options.tracker.lod_tolerance_m, 0.05);
  private_nh_.param("resume_tracks_by_resources", options.tracker.resume_by_resources, false);
  double alpha = 0.5;
  private_nh_.param("overlay_alpha", alpha, 0.5);
  if (!(alpha >= 0.0 && alpha <= 1.0)) {
    ROS_ERROR("%s: ~overlay_alpha must be in [0, 1] (got %g); using 0.5", me.c_str(), alpha);
    alpha = 0.5;
  }
  overlay_alpha_ = static_cast<float>(alpha);
  int queue_size = 10;
  private_nh_.param("queue_size", queue_size, 10);
  if (queue_size < 1) {
    ROS_ERROR("%s: ~queue_size must be >= 1 (got %d); using 10", me.c_str(), queue_size);
    queue_size = 10;
  }
  try {
    pipeline_ = std::make_unique<InstancePipeline>(LabelTable::load(label_path), options);
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

void Instances::onMeshStore(const MeshStore::ConstPtr& store) {
  std::vector<std::string> problems;
  std::vector<MeshRecord> meshes = fromMeshStoreMsg(*store, problems);
  for (const std::string& p : problems) ROS_ERROR_THROTTLE(5, "%s: %s", mesh_store_sub_.getTopic().c_str(), p.c_str());
  std::lock_guard<std::mutex> lock(mutex_);
  pipeline_->addMeshes(meshes);
}

void Instances::onColor(const sensor_msgs::Image::ConstPtr& color) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (overlay_pub_.getNumSubscribers() == 0) return;
  auto semantic = pending_semantic_.find(color->header.stamp);
  if (semantic != pending_semantic_.end()) {
    publishOverlay(*color, semantic->second);
    pending_semantic_.erase(pending_semantic_.begin(), std::next(semantic));
    return;
  }
  pending_color_[color->header.stamp] = color;
  while (pending_color_.size() > 8) pending_color_.erase(pending_color_.begin());
}

void Instances::publishOverlay(const sensor_msgs::Image& color, const std::vector<uint8_t>& semantic) {
  const size_t n = static_cast<size_t>(color.width) * color.height;
  std::string problem = checkImage(color, "rgb8");
  if (problem.empty() && semantic.size() != n)
    problem = "its " + std::to_string(n) + " pixels do not fit the " + std::to_string(semantic.size()) +
              "-pixel semantic image";
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s: color image: %s; no overlay", color_sub_.getTopic().c_str(), problem.c_str());
    return;
  }
  scratch_rgb_.resize(3 * n);
  overlayClasses(color.data.data(), semantic.data(), n, *classes_, overlay_alpha_, scratch_rgb_.data());
  overlay_pub_.publish(imageMsgPtr(color.header, color.width, color.height, "rgb8", 3, scratch_rgb_.data()));
}

void Instances::onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::Image::ConstPtr& ids) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string& topic = draw_ids_sub_.getTopic();
  if (!last_stamp_.isZero() && draws->header.stamp <= last_stamp_) {
    ROS_ERROR_THROTTLE(5, "%s: frame %lu stamp %.6f is not after the previous %.6f; frame dropped",
                       topic.c_str(), static_cast<unsigned long>(draws->frame_number), draws->header.stamp.toSec(),
                       last_stamp_.toSec());
    return;
  }
  const std::string problem = frameFromDrawMsgs(*draws, *ids, frame_);
  if (!problem.empty()) {
    ROS_ERROR_THROTTLE(5, "%s (frame %lu, frame_id '%s'): %s; frame dropped", topic.c_str(),
                       static_cast<unsigned long>(draws->frame_number), ids->header.frame_id.c_str(), problem.c_str());
    return;
  }
  try {
    pipeline_->process(frame_, result_);
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5, "%s: %s; frame dropped", topic.c_str(), e.what());
    return;
  }
  last_stamp_ = draws->header.stamp;
  for (const std::string& p : result_.problems) ROS_WARN_THROTTLE(5, "%s: %s", topic.c_str(), p.c_str());

  const std_msgs::Header& header = ids->header;
  const uint32_t w = frame_.width, h = frame_.height;
  const size_t n = frame_.pixelCount();
  if (semantic_pub_.getNumSubscribers() > 0)
    semantic_pub_.publish(imageMsgPtr(header, w, h, "mono8", 1, result_.semantic.data()));
  if (semantic_color_pub_.getNumSubscribers() > 0) {
    scratch_rgb_.resize(3 * n);
    colorizeClasses(result_.semantic.data(), n, *classes_, scratch_rgb_.data());
    semantic_color_pub_.publish(imageMsgPtr(header, w, h, "rgb8", 3, scratch_rgb_.data()));
  }
  if (overlay_pub_.getNumSubscribers() > 0) {
    auto color = pending_color_.find(header.stamp);
    if (color != pending_color_.end()) {
      publishOverlay(*color->second, result_.semantic);
      pending_color_.erase(pending_color_.begin(), std::next(color));
    } else {
      pending_semantic_[header.stamp] = result_.semantic;
      while (pending_semantic_.size() > 8) pending_semantic_.erase(pending_semantic_.begin());
    }
  }
  if (instance_ids_pub_.getNumSubscribers() > 0)
    instance_ids_pub_.publish(imageMsgPtr(header, w, h, "32SC1", 4, result_.instance_ids.data()));
  if (boundaries_pub_.getNumSubscribers() > 0)
    boundaries_pub_.publish(imageMsgPtr(header, w, h, "mono8", 1, result_.boundaries.data()));
  if (viper_pub_.getNumSubscribers() > 0) {
    scratch_rgb_.resize(3 * n);
    encodeViperInstances(result_.semantic.data(), result_.instance_ids.data(), n, scratch_rgb_.data());
    viper_pub_.publish(imageMsgPtr(header, w, h, "rgb8", 3, scratch_rgb_.data()));
  }
  objects_pub_.publish(toObjectArrayMsg(result_.objects, *classes_, header));
  ++frames_;
}

}  // namespace viper
