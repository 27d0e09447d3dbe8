// The odometry node's per-frame work without ROS plumbing: the camera body's pose in the map from
// the frame's view matrix, with velocities, as odometry, tf and path messages. The odometry node and
// the lockstep `generate` both run it (docs/ground_truth_nodes.md).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <viper/DrawList.h>

#include <optional>
#include <string>

namespace viper {

/// Settings of the odometry step (the odometry node's parameters, with the same defaults).
struct OdometrySettings {
  std::string map_frame = "map", body_frame = "camera";
  int path_max_poses = 10000;
  bool make_path = true;  ///< the path message (a copy of every pose so far, each frame)
};

class OdometryStep {
 public:
  /// Throws std::invalid_argument if the frames are empty or equal, or path_max_poses < 1.
  explicit OdometryStep(const OdometrySettings& settings);

  /// A frame's messages.
  struct Output {
    nav_msgs::OdometryPtr odom;                  ///< map -> body, twist from the previous frame
    geometry_msgs::TransformStamped map_to_body; ///< the same pose as tf
    geometry_msgs::TransformStamped body_to_optical;  ///< static; `optical_changed` when it is new
    bool optical_changed = false;
    nav_msgs::PathConstPtr path;                 ///< every pose so far (at most path_max_poses); null without make_path
  };
  /// One frame's draw list. Returns false if it was dropped (stamp not after the last, no camera,
  /// a view matrix that is not rigid).
  bool process(const DrawList& draws, Output& out, StepProblems& problems);

 private:
  OdometrySettings settings_;
  std::string optical_frame_;  // the optical frame of the last static transform
  std::optional<EgoPose> last_;
  ros::Time last_stamp_;
  nav_msgs::Path path_;
  CaptureFrame frame_;  // the last draw list's draws; converted into again (their storage reused)
};

}  // namespace viper
