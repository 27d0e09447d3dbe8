// Evaluation metrics as plug-ins: what a metric consumes (one frame pair of prediction and ground
// truth), what it accumulates (per condition and over all), and what it reports. Evaluation holds
// one object of every registered metric; the report and the evaluate node loop over them.
// Adding a metric: docs/design.md ("Adding to it").
#pragma once

#include "viper/evaluation/instance_metrics.h"
#include "viper/ground_truth/class_table.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace viper {

struct EvaluationSummary;

/// One vector of a sparse flow estimate: a point of the first frame (pixels, OpenCV convention:
/// integer coordinates are pixel centres) and its motion to the second frame (pixels, u right,
/// v down).
struct SparseFlowVector {
  double x = 0.0, y = 0.0, u = 0.0, v = 0.0;
};

/// Settings of an evaluation.
struct EvaluationOptions {
  /// KITTI segment lengths (m). KITTI uses 100..800 m; short sequences need shorter ones.
  std::vector<double> odometry_lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
  /// Every how many poses a KITTI segment starts (KITTI: 10).
  size_t odometry_step_frames = 10;
  /// Ground-truth instances smaller than this are ignored (Cityscapes: 100 px).
  int min_instance_px = 100;
  /// Thresholds (px) at which flow inlier curves are sampled for tables and plots.
  std::vector<double> curve_thresholds_px = defaultCurveThresholds();
  /// 0, 0.05, ..., 5 px.
  static std::vector<double> defaultCurveThresholds();
};

/// The inputs a metric reads from a frame; a bit mask of these is MetricInputs.
enum MetricInput : uint32_t {
  kGtSemantic = 1u << 0,       ///< EvalFrame::gt_semantic
  kGtInstanceIds = 1u << 1,    ///< EvalFrame::gt_instance_ids
  kGtFlow = 1u << 2,           ///< EvalFrame::gt_flow and gt_flow_visible
  kGtPose = 1u << 3,           ///< EvalFrame::gt_pose
  kPredSemantic = 1u << 4,     ///< EvalFrame::pred_semantic
  kPredInstances = 1u << 5,    ///< EvalFrame::pred_instances
  kPredFlow = 1u << 6,         ///< EvalFrame::pred_flow
  kPredSparseFlow = 1u << 7,   ///< EvalFrame::pred_sparse_flow
  kPredPose = 1u << 8,         ///< EvalFrame::pred_pose
};
using MetricInputs = uint32_t;
/// The prediction bits of a mask (the rest is ground truth).
constexpr MetricInputs kPredictionInputs = kPredSemantic | kPredInstances | kPredFlow | kPredSparseFlow | kPredPose;

/// One frame pair of ground truth and prediction. A metric reads only the inputs it declares;
/// the others may be null. Images are row-major without padding, width x height pixels; flows
/// interleaved (u, v) floats, NaN where undefined. Flow inputs belong to the pair (this frame,
/// next frame).
struct EvalFrame {
  std::string condition;      ///< the DrawList's condition tag
  uint64_t frame_number = 0;  ///< increasing within a sequence
  uint32_t width = 0, height = 0;
  const uint8_t* gt_semantic = nullptr;      ///< class ids
  const int32_t* gt_instance_ids = nullptr;  ///< 0 = no instance
  const float* gt_flow = nullptr;
  const uint8_t* gt_flow_visible = nullptr;  ///< non-zero: visible in the next frame; null: all visible
  const Eigen::Isometry3d* gt_pose = nullptr;  ///< camera (body frame) to world
  const uint8_t* pred_semantic = nullptr;
  const std::vector<BoxedInstance>* pred_instances = nullptr;
  const float* pred_flow = nullptr;
  const std::vector<SparseFlowVector>* pred_sparse_flow = nullptr;
  const Eigen::Isometry3d* pred_pose = nullptr;  ///< camera (body frame) to the estimate's world
  size_t pixels() const { return static_cast<size_t>(width) * height; }
};

/// What a metric is built from: the class table (names, scored classes) and the options.
struct MetricContext {
  ClassTable classes;
  EvaluationOptions options;
};

/// A column of a metric's report: a key (YAML and CSV), a label (Markdown) and the decimals shown.
struct ReportColumn {
  std::string key, label;
  int decimals = 2;
};

/// How the report shows a metric that reports through MetricScores: its headline numbers (a
/// column each in summary.md's table, a key each in the YAML block `key`), and optionally a
/// per-class table (Markdown section `title`, CSV file `<key>.csv`: condition,class_id,
/// class_name,<per_class.key>, then a "mean" row with headline[0]).
struct MetricLayout {
  std::string key;    ///< e.g. "semantic_iiou"
  std::string title;  ///< Markdown section title
  std::string note;   ///< Markdown text under the title (may be empty)
  std::vector<ReportColumn> headline;
  ReportColumn per_class;              ///< empty key: no per-class table
  std::vector<bool> classes;           ///< per class id: listed in the per-class table
};

/// The numbers of one metric for one condition (or all): `values` by headline key, `per_class`
/// per class id (NaN where not scored). Percentages are 0..100.
struct MetricScores {
  uint64_t frames = 0;
  std::map<std::string, double> values;
  std::vector<double> per_class;
};

/// One metric. Threads: add() of one object needs the caller's exclusion; different objects
/// may add at the same time.
class Metric {
 public:
  virtual ~Metric() = default;
  /// Unique name, e.g. "semantic" (what Evaluation::add() and the node know it by).
  virtual std::string name() const = 0;
  /// The inputs add() reads.
  virtual MetricInputs inputs() const = 0;
  /// Accumulates one frame pair into its condition's (and the overall) state. Returns how many
  /// units (pixels, vectors, poses) it scored. Throws std::invalid_argument on inconsistent input.
  virtual uint64_t add(const EvalFrame& frame) = 0;
  /// Frames added so far.
  virtual uint64_t frames() const = 0;
  /// The conditions it has seen.
  virtual std::vector<std::string> conditions() const = 0;
  /// Writes its numbers into `s` (whose conditions are filled in, in report order): the fields
  /// of ConditionSummary for the metrics of the original report, or `scores[name()]`.
  virtual void summarize(EvaluationSummary& s) const = 0;
  /// Its report layout when it reports through MetricScores; null for the metrics of the
  /// original report, whose tables eval_report.cpp writes.
  virtual const MetricLayout* layout() const { return nullptr; }
};

/// A metric's accumulator of one condition and the frames added to it.
template <typename Accumulator>
struct Counted {
  Accumulator acc;
  uint64_t frames = 0;
};

/// The conditions of a metric's per-condition state (for Metric::conditions()).
template <typename State>
std::vector<std::string> keysOf(const std::map<std::string, State>& by_condition) {
  std::vector<std::string> keys;
  for (const auto& entry : by_condition) keys.push_back(entry.first);
  return keys;
}

/// Builds a metric for an evaluation.
using MetricFactory = std::unique_ptr<Metric> (*)(const MetricContext&);

/// Every registered metric, in report order (src/evaluation/metric_registry.cpp).
const std::vector<MetricFactory>& registeredMetrics();

}  // namespace viper
