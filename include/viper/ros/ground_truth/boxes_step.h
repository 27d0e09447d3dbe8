// The boxes node's per-frame work without ROS plumbing: the oriented 3D box of every tracked object
// in the map frame and in the camera optical frame, with velocities. The boxes node and the
// lockstep `generate` both run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <Eigen/Geometry>

#include <map>
#include <string>

namespace viper {

class BoxesStep {
 public:
  BoxesStep(ClassTable classes, std::string map_frame);

  void addMeshes(const MeshStore& store, StepProblems& problems);

  /// A frame's boxes: in `map_frame` (always) and in the draws' optical frame (null when the frame
  /// has no usable view matrix).
  struct Output {
    Box3DArrayPtr in_map, in_optical;
  };
  /// One frame (the instances step's objects and the draw list of one stamp).
  void process(const ObjectArray& objects, const DrawList& draws, Output& out, StepProblems& problems);

  const ClassTable& classes() const { return classes_; }

 private:
  ClassTable classes_;
  std::string map_frame_;
  MeshRegistry meshes_;
  CaptureFrame frame_;  // the last draw list's draws; converted into again (their storage reused)
  struct LastSeen {
    Eigen::Vector3d center;
    double time_s;
  };
  std::map<int32_t, LastSeen> last_seen_;  // per track id, for velocities
};

}  // namespace viper
