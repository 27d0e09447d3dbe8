// Evaluation metrics as plug-ins: what a metric consumes (one frame pair of prediction and ground
// truth), what it accumulates (per condition and over all), and what it reports. Evaluation holds
// one object of every registered metric; the report and the evaluate node loop over them.
// Adding a metric: docs/design.md ("Adding to it").
#pragma once

#include "viper/evaluation/flow_metrics.h"
#include "viper/evaluation/instance_metrics.h"
#include "viper/ground_truth/class_table.h"
#include "viper/report/line_plot.h"

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
  /// Fill the missing vectors of a dense flow prediction before it is scored, as the KITTI devkit
  /// does (fillMissingFlow); false: a missing vector is an invalid prediction (an outlier).
  bool flow_fill_missing = false;
  /// How flow WAUC weighs the inlier curve: its integral (default) or its samples at 100
  /// thresholds (Spring's reading of VIPER's definition; docs/evaluate.md).
  WaucMode flow_wauc = WaucMode::kIntegral;
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

/// A number or text of a metric's report: where it comes from (`key`), what it is called there
/// (`label`: Markdown header, CSV header or YAML key) and how it is written.
struct ReportColumn {
  static constexpr int kCount = -1;     ///< decimals: a whole number (frames, pixels, segments)
  static constexpr int kShortest = -2;  ///< decimals: the shortest exact text (csvNumber), also in Markdown
  std::string key, label;
  int decimals = 2;  ///< Markdown decimals (CSV and YAML carry every number exactly)
};

/// A table of a metric's report, in summary.md (named by a MarkdownPart) and/or as a CSV file.
/// Per class: Markdown shows one row per listed class (MetricLayout::classes) with a score in any
/// condition, a column per condition and all, then a mean row (columns[0] and mean[0]); the CSV
/// has condition,class_id,class_name,<columns' keys> per listed class with a score, then a row
/// "<condition>,-1,mean,<mean values>", for every condition the metric scored.
/// Rows: condition, then `columns` for every row of the row sets `rows` (MetricScores::rows) of
/// every condition the metric scored (Markdown: "**all**"; CSV header: the columns' keys).
struct ReportTable {
  enum Kind { kPerClass, kRows };
  Kind kind = kPerClass;
  std::string name;  ///< what a MarkdownPart calls it
  std::string file;  ///< CSV file name ("flow.csv"); empty: only in Markdown
  bool always = false;  ///< the CSV is written even when nothing was scored (then header only); else removed
  std::vector<ReportColumn> columns;  ///< per class: keys of MetricScores::per_class
  std::vector<ReportColumn> mean;     ///< per class: keys of the mean row's values
  std::vector<std::string> rows;      ///< rows: the row sets, in order
  size_t left_aligned = 1;            ///< rows, Markdown: how many leading columns are aligned left
  std::string skip_zero;              ///< rows, Markdown: rows whose value of this key is 0 are left out
};

/// A piece of a metric's Markdown section: literal text, a table of its layout by name, or the
/// metric's note over all conditions (MetricScores::note of "all").
struct MarkdownPart {
  enum Kind { kText, kTable, kNote };
  Kind kind = kText;
  std::string text;  ///< the text, or the table's name
};

/// Curves over a common x as a CSV file: `x_label`, then one column per condition (and all) the
/// metric scored and curve, headed "<condition>/<curve label>"; a row per x.
struct CurveFile {
  std::string file, x_label;
  std::vector<double> x;
  std::vector<ReportColumn> curves;  ///< keys of MetricScores::curves
};

/// A PNG of a metric: panels side by side, each a LinePlot with one line per condition (and
/// all) whose value `when` is > 0 and per curve (legend "<condition> <curve label>", or the
/// condition alone where the label is empty). Written only if it has a line; else removed.
struct PlotLayout {
  struct Panel {
    LinePlot axes;  ///< without series
    std::vector<double> x;
    std::vector<ReportColumn> curves;  ///< keys of MetricScores::curves
  };
  std::string file;
  int width = 800, height = 500;  ///< of a panel
  std::string when = "frames";    ///< a key of MetricScores::values (or "frames")
  std::vector<Panel> panels;
};

/// How the report shows a metric; every part of the report loops over the registered metrics'
/// layouts (docs/evaluate.md). Metrics of one non-empty `group` (dense and sparse flow) share a
/// Markdown section (the first one's, shown if any of them scored) and files: the tables, curve
/// files and plots of the same name or file list, per condition, each metric's rows in turn.
struct MetricLayout {
  std::string key;           ///< Metric::name(): its MetricScores and its YAML block
  std::string group;
  std::string frames_label;  ///< in summary.md's "Frames scored" line; empty: not there
  std::vector<ReportColumn> summary;      ///< summary.md's table (when it scored)
  std::vector<ReportColumn> summary_csv;  ///< summary.csv (always)
  std::vector<ReportColumn> yaml;         ///< the running scores (when it scored)
  std::vector<MarkdownPart> markdown;     ///< its section (when it scored)
  std::vector<ReportTable> tables;
  std::vector<CurveFile> curve_files;     ///< always written
  std::vector<PlotLayout> plots;
  std::vector<bool> classes;              ///< per class id: listed in per-class tables
};

/// One row of a row table: text cells and numbers by column key (a text wins).
struct ReportRow {
  std::map<std::string, std::string> text;
  std::map<std::string, double> values;
};

/// The numbers of one metric for one condition (or all). Percentages are 0..100; NaN where
/// there is nothing to score.
struct MetricScores {
  uint64_t frames = 0;
  std::map<std::string, double> values;  ///< headline numbers and counts by key
  std::map<std::string, std::vector<double>> per_class;  ///< per class id, by key
  std::map<std::string, std::vector<ReportRow>> rows;    ///< row sets by key
  std::map<std::string, std::vector<double>> curves;     ///< y at the curve's x, by key
  std::string note;  ///< Markdown (MarkdownPart::kNote)
  /// values[key] (key "frames": frames), or NaN.
  double value(const std::string& key) const;
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
  /// Writes its numbers into `scores[name()]` of `s`'s conditions (filled in, in report order)
  /// and of `s.all`.
  virtual void summarize(EvaluationSummary& s) const = 0;
  /// How the report shows it.
  virtual const MetricLayout& layout() const = 0;
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
