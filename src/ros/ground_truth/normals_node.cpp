#include "viper/ros/ground_truth/normals_node.h"

#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/ground_truth/mesh_store_input.h"
#include "viper/ros/node_params.h"

#include <sensor_msgs/image_encodings.h>

namespace viper {

void NormalsMessageStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

sensor_msgs::ImagePtr NormalsMessageStep::process(const DrawList& draws, const sensor_msgs::ImageConstPtr& draw_ids,
                                                  const sensor_msgs::ImageConstPtr& primitive_ids,
                                                  const sensor_msgs::ImageConstPtr& depth, StepProblems& problems) {
  GroundTruthInput input;
  const unsigned long number = draws.frame_number;
  auto drop = [&](StepInput in, const char* kind, const std::string& problem) {
    problems.push_back({in, StepSeverity::kError, kind, " (frame " + std::to_string(number) + "): " + problem +
                                                           "; no normals for this frame"});
    return nullptr;
  };
  try {
    const std::string problem = decodeDrawMsgs(draws, draw_ids, input);
    if (!problem.empty()) return drop(StepInput::kDrawIds, "draw_ids", problem);
    std::string depth_problem, primitives_problem;
    decodeFlowMsgs(depth, primitive_ids, input, depth_problem, primitives_problem);
    if (!depth_problem.empty()) return drop(StepInput::kDepth, "depth", depth_problem);
    if (!primitives_problem.empty()) return drop(StepInput::kPrimitiveIds, "primitive_ids", primitives_problem);
  } catch (const std::exception& e) {
    return drop(StepInput::kDraws, "frame", e.what());
  }
  auto out = boost::make_shared<sensor_msgs::Image>();
  out->header = draw_ids->header;
  out->width = input.frame.width, out->height = input.frame.height;
  out->encoding = sensor_msgs::image_encodings::TYPE_32FC3;
  out->is_bigendian = false;
  out->step = 12 * out->width;
  out->data.resize(static_cast<size_t>(out->step) * out->height);
  if (!step_.process(input, chooseFrameCamera(input.frame), meshes_, reinterpret_cast<float*>(out->data.data()),
                     problems))
    return nullptr;
  return out;
}

Normals::Normals(const ros::NodeHandle& nh, const ros::NodeHandle& pnh)
    : nh_(nh), private_nh_(pnh), it_(nh), log_([this](StepInput input) { return topicOf(input); }) {}

Normals::~Normals() {
  normals_pub_.shutdown();
  if (inputs_) inputs_->stop();
  mesh_store_sub_.shutdown();
  std::lock_guard<std::mutex> lock(mutex_);
  step_.reset();
}

bool Normals::start() {
  queue_size_ = queueSizeParam(private_nh_);
  step_ = std::make_unique<NormalsMessageStep>();
  // The meshes always (a latched store, whole: only new meshes cost); the frames only while
  // someone listens.
  mesh_store_sub_ = nh_.subscribe("mesh_store", 1, &Normals::onMeshStore, this);
  sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(SyncPolicy(queue_size_), draws_sub_,
                                                                      draw_ids_sub_, primitive_ids_sub_, depth_sub_);
  sync_->registerCallback(&Normals::onFrame, this);
  inputs_ = std::make_unique<LazyInputs>(
      [this] {
        const image_transport::TransportHints raw("raw");
        draws_sub_.subscribe(nh_, "draws", queue_size_);
        draw_ids_sub_.subscribe(it_, "draw_ids", queue_size_, raw);
        primitive_ids_sub_.subscribe(it_, "primitive_ids", queue_size_, raw);
        depth_sub_.subscribe(it_, "depth", queue_size_, raw);
      },
      [this] {
        draws_sub_.unsubscribe(), draw_ids_sub_.unsubscribe(), primitive_ids_sub_.unsubscribe();
        depth_sub_.unsubscribe();
      });
  const image_transport::SubscriberStatusCallback changed = [this](const image_transport::SingleSubscriberPublisher&) {
    inputs_->update([this] { return normals_pub_.getNumSubscribers(); });
  };
  inputs_->advertise([&] {
    normals_pub_ = it_.advertise("normals", queue_size_, changed, changed);
  });
  return true;
}

std::string Normals::topicOf(StepInput input) const {
  switch (input) {
    case StepInput::kDraws: return draws_sub_.getTopic();
    case StepInput::kDrawIds: return draw_ids_sub_.getTopic();
    case StepInput::kPrimitiveIds: return primitive_ids_sub_.getTopic();
    case StepInput::kDepth: return depth_sub_.getTopic();
    case StepInput::kMeshStore: return mesh_store_sub_.getTopic();
    default: return defaultTopicOf(input);
  }
}

void Normals::onMeshStore(const MeshStore::ConstPtr& store) { addMeshStore(*store, step_, mutex_, cpu_, log_); }

void Normals::onFrame(const DrawList::ConstPtr& draws, const sensor_msgs::ImageConstPtr& draw_ids,
                      const sensor_msgs::ImageConstPtr& primitive_ids, const sensor_msgs::ImageConstPtr& depth) {
  const CpuMeter::Scope cpu(cpu_, true);
  StepProblems problems;
  sensor_msgs::ImagePtr out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    out = step_->process(*draws, draw_ids, primitive_ids, depth, problems);
  }
  log_.log(problems);
  if (out) normals_pub_.publish(out);
}

}  // namespace viper
