// The ego camera: drives (car), rides (motorcycle: lower, leaning and swaying) or walks along the
// town's route, obeying red lights and keeping its distance when on the road.
#pragma once

#include "math3d.h"
#include "traffic.h"
#include "town_layout.h"

#include <vector>

namespace viper {
namespace world {

/// How the ego moves.
enum class EgoMode { kDrive, kRide, kWalk };

/// Camera pose along the route, advanced with the simulation.
class Ego {
 public:
  /// Builds the path through the route's intersections (lane or sidewalk by mode).
  void init(const TownLayout& town, EgoMode mode);
  /// Advances by dt seconds at simulation time t (after the step).
  void step(const Traffic& traffic, double t, double dt);
  /// Camera body pose in the world (x forward, y left, z up).
  Mat4 cameraPose() const;
  /// World->OpenGL camera (looking down -Z, Y up) matrix.
  Mat4 viewMatrix() const;
  /// Camera position (m).
  Vec3 position() const;
  /// Where the ego sits on a lane, for other vehicles' car following.
  LaneSlot laneSlot() const;
  /// Length of the route path (m).
  double pathLength() const { return cum_.empty() ? 0.0 : cum_.back(); }
  /// Point of the path `s` metres from its start (clamped to the path; z = 0).
  Vec3 pathPoint(double s) const { return pointAt(s); }

 private:
  Vec3 pointAt(double s) const;
  int edgeAt(double s) const;

  const TownLayout* town_ = nullptr;
  EgoMode mode_ = EgoMode::kDrive;
  std::vector<Vec3> pts_;
  std::vector<double> cum_;
  std::vector<double> stop_s_;        ///< path position of each route intersection's stop line
  std::vector<double> edge_start_s_;  ///< straight part of each edge: [start, end]
  std::vector<double> edge_end_s_;
  double s_ = 0, v_ = 0, t_ = 0, lean_ = 0;
};

}  // namespace world
}  // namespace viper
