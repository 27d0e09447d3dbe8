// Visual odometry scores with the KITTI odometry protocol.
#pragma once

#include <Eigen/Geometry>

#include <vector>

namespace viper {

/// Error of one trajectory segment.
struct SegmentError {
  size_t first_frame = 0;
  double length_m = 0.0;          ///< nominal segment length (100, 200, ..., 800 m)
  double rotation_rad_per_m = 0.0;
  double translation_ratio = 0.0;  ///< translation error / length (multiply by 100 for %)
};

/// Aggregated scores.
struct OdometryScores {
  size_t segments = 0;
  double rotation_deg_per_m = 0.0;  ///< mean over all segments; NaN if there are none
  double translation_percent = 0.0;
  /// Per nominal length: number of segments and mean errors (for plots over segment length).
  std::vector<double> lengths_m;
  std::vector<size_t> segments_per_length;
  std::vector<double> rotation_deg_per_m_by_length, translation_percent_by_length;
};

/// KITTI odometry evaluation: for every 10th frame as a start and each length in 100..800 m, the
/// first frame at least that far along the ground-truth path ends the segment; the segment's error
/// is the relative pose error inv(gt_rel) * est_rel, rotation angle and translation norm divided by
/// the length. Poses are camera-to-world (any fixed world frame; estimated and ground truth each in
/// their own). Throws std::invalid_argument if the two trajectories differ in length.
/// Trajectories shorter than 100 m give zero segments and NaN scores.
std::vector<SegmentError> kittiSegmentErrors(const std::vector<Eigen::Isometry3d>& ground_truth,
                                             const std::vector<Eigen::Isometry3d>& estimate,
                                             const std::vector<double>& lengths_m = {100, 200, 300, 400, 500, 600, 700, 800},
                                             size_t step_frames = 10);

/// Averages segment errors as KITTI does (over all segments), and per length.
OdometryScores summarizeSegments(const std::vector<SegmentError>& errors,
                                 const std::vector<double>& lengths_m = {100, 200, 300, 400, 500, 600, 700, 800});

}  // namespace viper
