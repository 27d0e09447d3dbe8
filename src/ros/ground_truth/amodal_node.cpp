#include "viper/ros/ground_truth/amodal_node.h"

#include "viper/ros/conversions/amodal_conversions.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/ground_truth/mesh_store_input.h"
#include "viper/ros/node_params.h"

#include <sensor_msgs/image_encodings.h>

namespace viper {

void AmodalMessageStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

bool AmodalMessageStep::process(const DrawList& draws, const sensor_msgs::Image& instance_ids,
                                const ObjectArray& objects, FrameAmodal& amodal, StepProblems& problems) {
  const std::string at = " (frame " + std::to_string(draws.frame_number) + "): ";
  // The instance ids are named as the step names them (StepInput::kDrawIds: the node's topicOf
  // gives the instance_ids topic).
  const std::string problem = checkImage(instance_ids, sensor_msgs::image_encodings::TYPE_32SC1);
  if (!problem.empty()) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "instance_ids", at + problem + "; frame dropped"});
    return false;
  }
  try {
    fromDrawListMsg(draws, frame_);
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "draws", at + e.what() + "; frame dropped"});
    return false;
  }
  frame_.width = instance_ids.width, frame_.height = instance_ids.height;
  // Message buffers come from new[], aligned for any scalar type.
  step_.process(frame_, fromObjectArrayMsg(objects), reinterpret_cast<const int32_t*>(instance_ids.data.data()),
                meshes_, amodal, problems);
  return true;
}

Amodal::Amodal(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), it_(nh), log_([this](StepInput input) { return topicOf(input); }) {}

Amodal::~Amodal() {
  objects_pub_.shutdown();
  overlay_pub_.shutdown();
  if (inputs_) inputs_->stop();
  mesh_store_sub_.shutdown();
  std::lock_guard<std::mutex> lock(mutex_);
  step_.reset();
}

bool Amodal::start() {
  queue_size_ = queueSizeParam(private_nh_);
  step_ = std::make_unique<AmodalMessageStep>();
  // The meshes always (a latched store, whole: only new meshes cost); the frames only while
  // someone listens.
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Amodal::onMeshStore, this);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size_), draws_sub_,
                                                                      instance_ids_sub_, objects_sub_);
  sync_->registerCallback(&Amodal::onFrame, this);
  inputs_ = std::make_unique<LazyInputs>(
      [this] {
        draws_sub_.subscribe(nh_, "draws", queue_size_);
        instance_ids_sub_.subscribe(it_, "instance_ids", queue_size_, image_transport::TransportHints("raw"));
        objects_sub_.subscribe(nh_, "objects", queue_size_);
      },
      [this] { draws_sub_.unsubscribe(), instance_ids_sub_.unsubscribe(), objects_sub_.unsubscribe(); });
  auto subscribers = [this] { return objects_pub_.getNumSubscribers() + overlay_pub_.getNumSubscribers(); };
  const image_transport::SubscriberStatusCallback image_changed =
      [this, subscribers](const image_transport::SingleSubscriberPublisher&) { inputs_->update(subscribers); };
  const ros::SubscriberStatusCallback changed = [this, subscribers](const ros::SingleSubscriberPublisher&) {
    inputs_->update(subscribers);
  };
  inputs_->advertise([&] {
    objects_pub_ = nh_.advertise<AmodalInstanceArray>("amodal/objects", queue_size_, changed, changed);
    overlay_pub_ = it_.advertise("amodal/overlay", queue_size_, image_changed, image_changed);
  });
  return true;
}

std::string Amodal::topicOf(StepInput input) const {
  switch (input) {
    case StepInput::kDraws: return draws_sub_.getTopic();
    case StepInput::kDrawIds: return instance_ids_sub_.getTopic();  // the step's name for its id image
    case StepInput::kObjects: return objects_sub_.getTopic();
    case StepInput::kMeshStore: return mesh_store_sub_.getTopic();
    default: return defaultTopicOf(input);
  }
}

void Amodal::onMeshStore(const MeshStore::ConstPtr& store) { addMeshStore(*store, step_, mutex_, cpu_, log_); }

void Amodal::onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::ImageConstPtr& instance_ids,
                     const ObjectArray::ConstPtr& objects) {
  const CpuMeter::Scope cpu(cpu_, true);
  StepProblems problems;
  AmodalInstanceArray::Ptr objects_msg;
  sensor_msgs::ImagePtr overlay;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (step_->process(*draws, *instance_ids, *objects, amodal_, problems)) {
      if (objects_pub_.getNumSubscribers() > 0)
        objects_msg = boost::make_shared<AmodalInstanceArray>(toAmodalInstanceArrayMsg(amodal_, instance_ids->header));
      if (overlay_pub_.getNumSubscribers() > 0) {
        overlay = boost::make_shared<sensor_msgs::Image>();
        renderAmodalOverlay(amodal_, reinterpret_cast<const int32_t*>(instance_ids->data.data()),
                            instance_ids->header, *overlay);
      }
    }
  }
  log_.log(problems);
  if (objects_msg) objects_pub_.publish(objects_msg);
  if (overlay) overlay_pub_.publish(overlay);
}

}  // namespace viper
