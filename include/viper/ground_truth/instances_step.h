// The instances node's per-frame work on core types: objects, classes, tracks and the segmentation
// images of one frame, frames taken in stamp order. The instances node (through its messages,
// src/ros/ground_truth/instances_step.cpp) and the lockstep `generate` (GroundTruthPipeline) both
// run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ground_truth/step_problems.h"

#include <memory>
#include <vector>

namespace viper {

/// Settings of the instances step (the instances node's parameters, with the same defaults).
struct InstancesSettings {
  bool area_weighted_vote = true;
  int extrapolate_frames = 10;
  double lod_tolerance_m = 0.05;
  bool resume_tracks_by_resources = false;
};

class InstancesStep {
 public:
  /// Throws std::invalid_argument if a setting is out of range (extrapolate_frames < 0).
  InstancesStep(LabelTable labels, ClassTable classes, const InstancesSettings& settings);

  /// Meshes that arrive outside frames (a mesh store).
  void addMeshes(const std::vector<MeshRecord>& meshes) { pipeline_->addMeshes(meshes); }
  /// Every mesh so far (the boxes and flow steps of one pipeline read it too).
  const MeshRegistry& meshes() const { return pipeline_->meshes(); }

  /// Whether a frame of `stamp` comes after the last one processed; if not, says so in `problems`
  /// (the frame is then dropped).
  bool inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const;
  /// One frame: `frame`'s size, number, time and draws with its draw ids at `draw_ids`. The images
  /// go where `into` says (InstanceImagesInto; its draw_ids is `draw_ids`), into `out`'s vectors
  /// where it says nothing; objects and the pipeline's problems into `out`. Returns false if the
  /// frame was dropped (a stamp not after the last, draws the pipeline refuses), with `problems`
  /// saying why.
  bool process(const CaptureFrame& frame, const FrameStamp& stamp, const uint32_t* draw_ids, InstanceImagesInto into,
               InstanceFrame& out, StepProblems& problems);

  const ClassTable& classes() const { return classes_; }

 private:
  ClassTable classes_;
  std::unique_ptr<InstancePipeline> pipeline_;
  FrameStamp last_stamp_;
};

}  // namespace viper
