// The boxes node's per-frame work on messages: its draw list and the instances node's objects
// decoded, the core BoxesStep (include/viper/ground_truth/boxes_step.h) run on them, and the boxes
// as messages (ground_truth_conversions.h, which `generate` converts with too).
#pragma once

#include "viper/ground_truth/boxes_step.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <string>

namespace viper {

class BoxesMessageStep {
 public:
  BoxesMessageStep(ClassTable classes, std::string map_frame) : step_(std::move(classes)), map_frame_(std::move(map_frame)) {}

  void addMeshes(const MeshStore& store, StepProblems& problems);

  /// One frame (the instances step's objects and the draw list of one stamp): its boxes in
  /// `map_frame` (always) and in the draws' optical frame (null when the frame has no usable view
  /// matrix).
  void process(const ObjectArray& objects, const DrawList& draws, BoxesMessages& out, StepProblems& problems);

  const ClassTable& classes() const { return step_.classes(); }

 private:
  BoxesStep step_;
  std::string map_frame_;
  MeshRegistry meshes_;
  CaptureFrame frame_;  // the last draw list's draws; converted into again (their storage reused)
  FrameBoxes boxes_;    // the same
};

}  // namespace viper
