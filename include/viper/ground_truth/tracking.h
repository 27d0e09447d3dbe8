// Tracking of objects over frames: association as a matching problem (docs/ground_truth.md,
// "Tracking").
#pragma once

#include "viper/ground_truth/objects.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace viper {

/// Tracker parameters.
struct TrackerOptions {
  /// Per class id: the largest plausible speed in m/s (an edge needs motion <= speed * dt + slack).
  std::vector<double> max_speed_mps = defaultMaxSpeeds();
  /// Per class id: whether the class is dynamic (then an edge also needs a shared resource, or a
  /// position within `lod_tolerance_m` of the prediction: a level-of-detail swap).
  std::vector<bool> dynamic_classes = defaultDynamicClasses();
  /// Slack added to every motion limit (m), for numerical noise and very short frame times.
  double slack_m = 0.05;
  /// A dynamic object whose resources all changed still continues its track if it is this close
  /// to where the track was predicted (m).
  double lod_tolerance_m = 0.05;
  /// Frames a vanished track is extrapolated linearly and can be picked up again.
  int extrapolate_frames = 10;
  /// A dynamic object that comes back after longer than that takes up its old track again when its
  /// resources are all among that track's and among no other's of its class (programs whose every
  /// moving object has resources of its own: a game's karts). Off by default: where objects share
  /// models (a town's pedestrians and traffic) only the window above holds ids.
  bool resume_by_resources = false;

  /// Speeds for the VIPER classes: people 10 m/s, vehicles 60 m/s, static things 0.5 m/s.
  static std::vector<double> defaultMaxSpeeds();
  /// VIPER's dynamic classes: person, animal, bicycle, motorcycle, car, van, bus, truck, trailer,
  /// train, plane, boat.
  static std::vector<bool> defaultDynamicClasses();
};

/// Assigns stable track ids to the thing objects of consecutive frames.
class Tracker {
 public:
  explicit Tracker(TrackerOptions options = TrackerOptions());

  /// Associates the frame's objects with the tracks and returns per object its track id
  /// (>= 1; 0 for objects that are not things). `positions[k]` is objects[k]'s position in the
  /// world (m). `time_s` must increase; a frame with time <= the previous one resets the tracker
  /// (and is reported by wasReset()).
  std::vector<int32_t> update(double time_s, const std::vector<FrameObject>& objects,
                              const std::vector<Eigen::Vector3d>& positions);

  /// Whether the last update() reset the tracker because time did not increase.
  bool wasReset() const { return was_reset_; }
  /// Forgets every track (ids keep increasing, so an id is never reused).
  void reset();
  size_t liveTracks() const { return tracks_.size(); }

 private:
  struct Track {
    int32_t id;
    uint8_t class_id;
    Eigen::Vector3d position, velocity;
    double time_s;
    int missed;
    std::vector<uint64_t> resources;  // every mesh and texture key seen on this track (sorted)
  };
  bool edgeAllowed(const Track& t, const FrameObject& o, const Eigen::Vector3d& predicted,
                   const Eigen::Vector3d& position, double dt) const;

  TrackerOptions options_;
  std::vector<Track> tracks_;
  std::vector<Track> dormant_;  ///< tracks past the window, for resume_by_resources (newest last)
  /// The dormant track an object takes up again (resume_by_resources), or -1.
  int resumable(const FrameObject& o, const std::vector<uint64_t>& resources) const;
  int32_t next_id_ = 1;
  double last_time_s_ = 0.0;
  bool have_time_ = false, was_reset_ = false;
};

}  // namespace viper
