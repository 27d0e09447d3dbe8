// The accumulators of an evaluation run, per condition and over all: what the `evaluate` node
// feeds frame by frame and what its report and running scores are made from.
#pragma once

#include "viper/evaluation/flow_metrics.h"
#include "viper/evaluation/metric.h"
#include "viper/evaluation/odometry_metrics.h"
#include "viper/evaluation/semantic_metrics.h"
#include "viper/ground_truth/class_table.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace viper {

/// Numbers of one flow accumulator.
struct FlowSummary {
  uint64_t frames = 0;
  uint64_t pixels = 0;   ///< scored pixels (sparse: scored vectors)
  uint64_t invalid = 0;  ///< scored pixels whose prediction is not finite
  double wauc = 0.0;     ///< 0..100
  double epe_px = 0.0;
  double outlier_percent = 0.0;  ///< KITTI Fl: error > 3 px and > 5 % of the true motion
  std::vector<double> inlier_percent;  ///< at EvaluationOptions::curve_thresholds_px
  bool present() const { return frames > 0; }
};

/// Everything scored for one condition, or over all of them. Percentages are 0..100; a NaN means
/// "nothing to score" (e.g. a class absent from the ground truth).
struct ConditionSummary {
  std::string condition;
  // Semantic segmentation.
  uint64_t semantic_frames = 0;
  uint64_t semantic_pixels = 0;
  double mean_iou = 0.0;
  std::vector<double> iou;  ///< per class id, percent; NaN where not scored
  // Instance segmentation (Cityscapes AP over IoU 0.50:0.05:0.95, and at 0.50).
  uint64_t instance_frames = 0;
  double ap = 0.0, ap50 = 0.0;
  std::vector<double> class_ap, class_ap50;  ///< per class id, percent
  // Optical flow: dense and sparse, on every pixel with ground truth ("all") and on pixels
  // visible in the second frame ("noc").
  FlowSummary flow_all, flow_noc, sparse_all, sparse_noc;
  uint64_t sparse_vectors = 0;  ///< received, including those outside the image
  // Visual odometry (KITTI).
  uint64_t odometry_poses = 0;
  size_t odometry_sequences = 0;  ///< contiguous runs of poses of this condition
  double odometry_path_m = 0.0;   ///< ground-truth path length over those runs
  OdometryScores odometry;
  /// The metrics that report through MetricScores, by Metric::name().
  std::map<std::string, MetricScores> scores;
  /// scores[metric], or empty scores (no frames) if it has none.
  const MetricScores& scoresOf(const std::string& metric) const;
};

/// A summary of the whole evaluation.
struct EvaluationSummary {
  std::vector<std::string> class_names;  ///< per class id
  std::vector<bool> semantic_eval, instance_eval;
  std::vector<double> curve_thresholds_px;
  std::vector<ConditionSummary> conditions;  ///< day, sunset, rain, snow, night, then others by name
  ConditionSummary all;
  /// The layouts of the metrics that report through MetricScores, in registration order.
  std::vector<MetricLayout> layouts;
};

/// Accumulates every registered metric (metric.h) per condition (the DrawList's condition tag).
/// Threads: adds to different metrics may run at the same time; adds to one metric, and
/// summarize() or framesAdded() with any add, need the caller's exclusion.
/// Images are row-major without padding, `n` pixels; flows interleaved (u, v) floats, NaN where
/// undefined.
class Evaluation {
 public:
  /// The class table gives the names and which classes are scored; void classes (for instance
  /// AP) are those without class_eval. Builds one object of every registered metric. Throws
  /// std::invalid_argument on an empty table or impossible options.
  explicit Evaluation(const ClassTable& classes, EvaluationOptions options = {});
  Evaluation(Evaluation&&) noexcept;
  Evaluation& operator=(Evaluation&&) noexcept;
  ~Evaluation();

  /// The metrics, in registration order.
  const std::vector<std::unique_ptr<Metric>>& metrics() const { return metrics_; }
  /// The metric called `name`, or null.
  Metric* metric(const std::string& name) const;
  /// Adds one frame pair to the metric called `name`; returns what Metric::add() returns.
  /// Throws std::invalid_argument for an unknown metric, or what the metric throws.
  uint64_t add(const std::string& name, const EvalFrame& frame);

  /// Semantic class ids of ground truth and prediction (metric "semantic"). Throws
  /// std::invalid_argument on null pointers.
  void addSemantic(const std::string& condition, const uint8_t* gt, const uint8_t* pred, size_t n);
  /// Ground-truth instance ids (0 = none) and class ids, and the predicted instances (full-frame
  /// masks of n pixels; metric "instances"). Throws std::invalid_argument if a mask has another size.
  void addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes, size_t n,
                    const std::vector<PredictedInstance>& predictions);
  /// The same for masks given in boxes of a width x height frame. Throws std::invalid_argument if
  /// a box leaves the frame or a non-empty box has no mask.
  void addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes, uint32_t width,
                    uint32_t height, const std::vector<BoxedInstance>& predictions);
  /// Dense flow of the same frame pair (metric "flow"); `visible` (non-zero = visible in the
  /// second frame) selects the non-occluded pixels, and may be null (then "noc" equals "all").
  void addFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible, const float* pred_uv,
               size_t n);
  /// Sparse flow of the same frame pair (metric "flow_sparse"): each vector is scored against the
  /// ground truth at the pixel nearest its point; points outside the w x h image are not scored.
  /// Returns how many vectors were scored (ground truth defined there).
  size_t addSparseFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible, uint32_t width,
                       uint32_t height, const std::vector<SparseFlowVector>& flow);
  /// One pose pair (metric "odometry"; camera to world: ground truth and estimate, each in its
  /// own world frame). Poses of one condition with increasing frame numbers form one trajectory;
  /// another condition or a frame number that does not increase starts a new one.
  void addPose(const std::string& condition, uint64_t frame_number, const Eigen::Isometry3d& gt,
               const Eigen::Isometry3d& estimate);

  /// Every number, per condition and over all.
  EvaluationSummary summarize() const;
  /// Frames added so far, over every metric (a pose counts as a frame).
  uint64_t framesAdded() const;

 private:
  ClassTable classes_;
  EvaluationOptions options_;
  std::vector<std::unique_ptr<Metric>> metrics_;
};

}  // namespace viper
