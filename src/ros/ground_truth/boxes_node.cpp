#include "viper/ros/ground_truth/boxes_node.h"
#include "viper/ros/ground_truth/mesh_store_input.h"
#include "viper/ros/node_params.h"

#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/ground_truth/instances_node.h"  // loadClassTableParam

namespace viper {

Boxes::Boxes(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), log_([this](StepInput input) { return topicOf(input); }) {}

bool Boxes::start() {
  std::optional<ClassTable> classes = loadClassTableParam(private_nh_);
  if (!classes) return false;
  std::string map_frame;
  private_nh_.param<std::string>("map_frame", map_frame, "map");
  const int queue_size = queueSizeParam(private_nh_);
  step_ = std::make_unique<BoxesMessageStep>(std::move(*classes), map_frame);
  boxes_pub_ = nh_.advertise<Box3DArray>("boxes", queue_size);
  boxes_optical_pub_ = nh_.advertise<Box3DArray>("boxes_optical", queue_size);
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("box_markers", queue_size);
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Boxes::onMeshStore, this);
  objects_sub_.subscribe(nh_, "objects", queue_size);
  draws_sub_.subscribe(nh_, "draws", queue_size);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size), objects_sub_, draws_sub_);
  sync_->registerCallback(&Boxes::onFrame, this);
  return true;
}

std::string Boxes::topicOf(StepInput input) const {
  switch (input) {
    case StepInput::kObjects: return objects_sub_.getTopic();
    case StepInput::kDraws: return draws_sub_.getTopic();
    case StepInput::kMeshStore: return mesh_store_sub_.getTopic();
    default: return defaultTopicOf(input);
  }
}

void Boxes::onMeshStore(const MeshStore::ConstPtr& store) { addMeshStore(*store, step_, mutex_, cpu_, log_); }

void Boxes::onFrame(const ObjectArray::ConstPtr& objects, const DrawList::ConstPtr& draws) {
  const CpuMeter::Scope cpu(cpu_, true);
  BoxesMessages out;
  StepProblems problems;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    step_->process(*objects, *draws, out, problems);
  }
  log_.log(problems);
  boxes_pub_.publish(out.in_map);
  if (out.in_optical) boxes_optical_pub_.publish(out.in_optical);
  if (markers_pub_.getNumSubscribers() > 0) markers_pub_.publish(boxMarkers(*out.in_map, step_->classes()));
}

}  // namespace viper
