// The odometry node's per-frame work on messages: its draw list's camera, the core OdometryStep
// (include/viper/ground_truth/odometry_step.h) run on it, and the pose as odometry, tf and path
// messages (OdometryMessages, which `generate` converts with too).
#pragma once

#include "viper/ground_truth/odometry_step.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <viper/DrawList.h>

namespace viper {

class OdometryMessageStep {
 public:
  /// Throws std::invalid_argument if the frames are empty or equal, or path_max_poses < 1.
  explicit OdometryMessageStep(const OdometrySettings& settings) : messages_(settings) {}

  using Output = OdometryMessages::Output;
  /// One frame's draw list. Returns false if it was dropped (stamp not after the last, no camera,
  /// a view matrix that is not rigid).
  bool process(const DrawList& draws, Output& out, StepProblems& problems);

 private:
  OdometryStep step_;
  OdometryMessages messages_;
  CaptureFrame frame_;  // the last draw list's draws; converted into again (their storage reused)
};

}  // namespace viper
