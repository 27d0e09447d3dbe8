#include "viper/ros/ground_truth/flow_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/scene_flow.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <stdexcept>

namespace viper {

float* FlowMessageStep::Pools::takeSceneFlow(const GroundTruthInput& from) {
  // computeSceneFlow writes every pixel: a recycled message needs no clearing.
  scene_flow = scene_pool_.take(headerOf(from), from.frame.width, from.frame.height,
                                sensor_msgs::image_encodings::TYPE_32FC4, 4 * kSceneFlowChannels);
  return reinterpret_cast<float*>(scene_flow->data.data());
}

void FlowMessageStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

bool FlowMessageStep::process(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
                              const sensor_msgs::ImageConstPtr& draw_ids,
                              const sensor_msgs::ImageConstPtr& primitive_ids, const ObjectArray& objects,
                              const Want& want, Output& out, StepProblems& problems) {
  out = Output();
  pools_.clear();
  pools_.clearScene();
  const unsigned long number = draws.frame_number;
  if (!step_.inOrder(toFrameStamp(draws.header.stamp), number, problems)) return false;
  // A frame of its own: the window holds it (and the messages its pixels are in).
  auto input = std::make_shared<GroundTruthInput>();
  auto drop = [&](StepInput in, const char* kind, const std::string& problem) {
    problems.push_back({in, StepSeverity::kError, kind, " (frame " + std::to_string(number) + "): " + problem +
                                                           "; frame dropped"});
    step_.startOver();  // the sequence is broken: no flow spans the dropped frame
    return false;
  };
  try {
    std::string problem = decodeDrawMsgs(draws, draw_ids, *input);
    if (!problem.empty()) return drop(StepInput::kDrawIds, "draw_ids", problem);
    std::string depth_problem, primitives_problem;
    decodeFlowMsgs(depth, primitive_ids, *input, depth_problem, primitives_problem);
    if (!depth_problem.empty()) return drop(StepInput::kDepth, "depth", depth_problem);
    if (!primitives_problem.empty()) return drop(StepInput::kPrimitiveIds, "primitive_ids", primitives_problem);
  } catch (const std::exception& e) {
    return drop(StepInput::kDraws, "frame", e.what());
  }
  FlowStep::Output computed;
  const bool kept = step_.process(input, chooseFrameCamera(input->frame), fromObjectArrayMsg(objects), meshes_, want,
                                  pools_, computed, problems);
  if (!kept) return false;
  if (computed.forward) out.forward = pools_.messages(FlowKind::kForward);
  if (computed.backward) out.backward = pools_.messages(FlowKind::kBackward);
  if (computed.wide) out.wide = pools_.messages(FlowKind::kWide);
  if (computed.scene_flow) out.scene_flow = pools_.scene_flow;
  return true;
}

void FlowMessageStep::correspondences(const ros::Time& stamp_a, const ros::Time& stamp_b,
                                      Correspondences::Response& res, StepProblems& problems) {
  const FrameStamp a = toFrameStamp(stamp_a), b = toFrameStamp(stamp_b);
  const GroundTruthInput* held_a = step_.held(a);
  if (!held_a || !step_.held(b)) {
    res.success = false;
    res.message = std::string("stamp ") + (held_a ? "b " + std::to_string(stamp_b.toSec()) : "a " + std::to_string(stamp_a.toSec())) +
                  " is not held; held: [" + step_.heldStamps() + "]";
    return;
  }
  try {
    shapeFlowMsgs(held_a->frame.width, held_a->frame.height, headerOf(*held_a), res.flow, res.visible);
    step_.flowBetween(a, b, meshes_,
                      FlowBuffers{reinterpret_cast<float*>(res.flow.data.data()), res.visible.data.data()}, problems);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
    return;
  }
  const std::optional<Eigen::Isometry3d> b_in_a = step_.relativePose(a, b);
  res.pose_valid = b_in_a.has_value();
  if (res.pose_valid) res.b_in_a = toTransformMsg(*b_in_a);
  res.success = true;
}

}  // namespace viper
