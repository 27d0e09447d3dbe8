#include "viper/evaluation/odometry_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {

std::vector<SegmentError> kittiSegmentErrors(const std::vector<Eigen::Isometry3d>& gt,
                                             const std::vector<Eigen::Isometry3d>& est,
                                             const std::vector<double>& lengths_m, size_t step_frames) {
  if (gt.size() != est.size())
    throw std::invalid_argument("kittiSegmentErrors: ground truth has " + std::to_string(gt.size()) +
                                " poses, estimate " + std::to_string(est.size()));
  if (step_frames == 0) throw std::invalid_argument("kittiSegmentErrors: step_frames must be > 0");
  std::vector<double> dist(gt.size(), 0.0);
  for (size_t i = 1; i < gt.size(); ++i)
    dist[i] = dist[i - 1] + (gt[i].translation() - gt[i - 1].translation()).norm();

  std::vector<SegmentError> errors;
  for (size_t first = 0; first < gt.size(); first += step_frames) {
    for (double len : lengths_m) {
      // KITTI ends a segment at the first frame strictly farther than the length.
      const auto it = std::upper_bound(dist.begin() + first, dist.end(), dist[first] + len);
      if (it == dist.end()) continue;
      const size_t last = static_cast<size_t>(it - dist.begin());
      const Eigen::Isometry3d gt_rel = gt[first].inverse() * gt[last];
      const Eigen::Isometry3d est_rel = est[first].inverse() * est[last];
      const Eigen::Isometry3d err = est_rel.inverse() * gt_rel;
      const double cos_angle = std::clamp(0.5 * (err.linear().trace() - 1.0), -1.0, 1.0);
      SegmentError e;
      e.first_frame = first;
      e.length_m = len;
      e.rotation_rad_per_m = std::acos(cos_angle) / len;
      e.translation_ratio = err.translation().norm() / len;
      errors.push_back(e);
    }
  }
  return errors;
}

OdometryScores summarizeSegments(const std::vector<SegmentError>& errors, const std::vector<double>& lengths_m) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double deg = 180.0 / M_PI;
  OdometryScores s;
  s.segments = errors.size();
  double r = 0.0, t = 0.0;
  for (const auto& e : errors) r += e.rotation_rad_per_m, t += e.translation_ratio;
  s.rotation_deg_per_m = errors.empty() ? nan : deg * r / errors.size();
  s.translation_percent = errors.empty() ? nan : 100.0 * t / errors.size();
  for (double len : lengths_m) {
    size_t n = 0;
    double rl = 0.0, tl = 0.0;
    for (const auto& e : errors)
      if (e.length_m == len) ++n, rl += e.rotation_rad_per_m, tl += e.translation_ratio;
    s.lengths_m.push_back(len);
    s.segments_per_length.push_back(n);
    s.rotation_deg_per_m_by_length.push_back(n == 0 ? nan : deg * rl / n);
    s.translation_percent_by_length.push_back(n == 0 ? nan : 100.0 * tl / n);
  }
  return s;
}

}  // namespace viper
