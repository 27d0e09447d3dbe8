// The boxes node's per-frame work on core types: the oriented 3D box of every tracked object in the
// map (world) frame and in the camera optical frame, with velocities. The boxes node (through its
// messages, src/ros/ground_truth/boxes_step.cpp) and the lockstep `generate` (GroundTruthPipeline)
// both run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/step_problems.h"

#include <Eigen/Geometry>

#include <map>
#include <optional>
#include <vector>

namespace viper {

/// The box of one tracked object in a frame.
struct TrackBox {
  int32_t track_id = 0;
  uint8_t class_id = 0;
  OrientedBox in_map;
  Eigen::Vector3d velocity_map = Eigen::Vector3d::Zero();  ///< m/s, from the track's last box (0 for a new one)
  OrientedBox in_optical;                                  ///< meaningful when FrameBoxes::has_optical
  Eigen::Vector3d velocity_optical = Eigen::Vector3d::Zero();
};

/// A frame's boxes, in the order of the objects; `has_optical` when the frame has a usable view
/// matrix (else the boxes have no optical-frame pose).
struct FrameBoxes {
  std::vector<TrackBox> boxes;
  bool has_optical = false;
};

class BoxesStep {
 public:
  /// `classes` names the objects' classes in problems.
  explicit BoxesStep(ClassTable classes);

  /// One frame: the draws of `frame` (their world matrices place the objects), its camera (as
  /// chooseFrameCamera gives it), the objects of the instances step (tracked ones get a box: track
  /// id > 0) and the meshes so far.
  void process(const CaptureFrame& frame, const FrameStamp& stamp, const std::optional<FrameCamera>& camera,
               const std::vector<TrackedObject>& objects, const MeshRegistry& meshes, FrameBoxes& out,
               StepProblems& problems);

  const ClassTable& classes() const { return classes_; }

 private:
  ClassTable classes_;
  struct LastSeen {
    Eigen::Vector3d center;
    double time_s;
  };
  std::map<int32_t, LastSeen> last_seen_;  // per track id, for velocities
};

}  // namespace viper
