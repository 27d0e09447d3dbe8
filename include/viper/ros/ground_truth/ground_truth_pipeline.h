// Every ground-truth step in lockstep, without a ROS master: one raw frame in, all its ground truth
// out, in the order and with the code the nodes of replay.launch use (instances, then boxes,
// odometry and flow on its objects). The `generate` command runs it; a frame is never dropped for
// being slow.
#pragma once

#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ground_truth/stage_times.h"
#include "viper/ros/ground_truth/boxes_step.h"
#include "viper/ros/ground_truth/flow_step.h"
#include "viper/ros/ground_truth/instances_step.h"
#include "viper/ros/ground_truth/odometry_step.h"

#include <memory>

namespace viper {

/// Settings of every step (the nodes' parameters).
struct GroundTruthSettings {
  InstancesSettings instances;
  FlowSettings flow;
  OdometrySettings odometry;
  bool flow_enabled = true;  ///< replay.launch flow:=
};

/// The ground truth of one frame, each null where a step dropped the frame or made nothing.
struct GroundTruthMessages {
  InstancesStep::Output instances;  ///< semantic, semantic_color, instance_ids, boundaries, instances_viper, objects
  BoxesStep::Output boxes;          ///< in map and in the optical frame
  std::optional<OdometryStep::Output> odometry;
  FlowStep::Output flow;            ///< forward and backward between the previous frame and this one
};

class GroundTruthPipeline {
 public:
  GroundTruthPipeline(LabelTable labels, ClassTable classes, const GroundTruthSettings& settings);

  /// One raw frame: its mesh store (if any) first, then every step. Returns false if the instances
  /// step dropped the frame (nothing else is computed then).
  /// With `times`, each step's CPU and wall time is added to it (stages "odometry", "instances",
  /// "boxes", "flow").
  bool process(const FrameMessages& raw, GroundTruthMessages& out, StepProblems& problems,
               StageTimes* times = nullptr);

  const ClassTable& classes() const { return instances_.classes(); }

 private:
  GroundTruthSettings settings_;
  InstancesStep instances_;
  BoxesStep boxes_;
  OdometryStep odometry_;
  FlowStep flow_;
};

}  // namespace viper
