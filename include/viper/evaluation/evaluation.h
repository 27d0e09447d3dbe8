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

/// Everything scored for one condition, or over all of them: each metric's numbers by
/// Metric::name() (what they mean: the metric's file in src/evaluation/metrics/).
struct ConditionSummary {
  std::string condition;
  std::map<std::string, MetricScores> scores;
  /// scores[metric], or empty scores (no frames) if it has none.
  const MetricScores& scoresOf(const std::string& metric) const;
};

/// A summary of the whole evaluation.
struct EvaluationSummary {
  std::vector<std::string> class_names;  ///< per class id
  std::vector<ConditionSummary> conditions;  ///< day, sunset, rain, snow, night, then others by name
  ConditionSummary all;
  /// The metrics' layouts, in registration order.
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
