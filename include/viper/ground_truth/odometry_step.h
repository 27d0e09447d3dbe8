// The odometry node's per-frame work on core types: the camera body's pose in the map from the
// frame's view matrix, with its velocity since the previous frame. The odometry node (through its
// messages, src/ros/ground_truth/odometry_step.cpp) and the lockstep `generate`
// (GroundTruthPipeline) both run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/step_problems.h"

#include <optional>

namespace viper {

/// The camera's motion at one frame.
struct EgoFrame {
  EgoPose pose;                     ///< at the frame's stamp
  std::optional<BodyTwist> twist;   ///< from the previous frame's pose; none for the first frame
};

class OdometryStep {
 public:
  /// Whether a frame of `stamp` comes after the last one processed; if not, says so in `problems`
  /// (the frame is then dropped).
  bool inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const;
  /// One frame: its camera (as chooseFrameCamera gives it), stamp and number. Returns false if it
  /// was dropped (a stamp not after the last, no camera, a view matrix that is not rigid).
  bool process(const std::optional<FrameCamera>& camera, const FrameStamp& stamp, uint64_t number, EgoFrame& out,
               StepProblems& problems);

 private:
  std::optional<EgoPose> last_;
  FrameStamp last_stamp_;
};

}  // namespace viper
