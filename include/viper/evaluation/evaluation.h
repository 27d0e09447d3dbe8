// The accumulators of an evaluation run, per condition and over all: what the `evaluate` node
// feeds frame by frame and what its report and running scores are made from.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/evaluation/flow_metrics.h"
#include "viper/evaluation/instance_metrics.h"
#include "viper/evaluation/odometry_metrics.h"
#include "viper/evaluation/semantic_metrics.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace viper {

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
};

/// A summary of the whole evaluation.
struct EvaluationSummary {
  std::vector<std::string> class_names;  ///< per class id
  std::vector<bool> semantic_eval, instance_eval;
  std::vector<double> curve_thresholds_px;
  std::vector<ConditionSummary> conditions;  ///< day, sunset, rain, snow, night, then others by name
  ConditionSummary all;
};

/// Accumulates every metric per condition (the DrawList's condition tag).
/// Threads: adds of different metrics (semantic, instances, dense flow, sparse flow, poses) may run
/// at the same time; adds of one metric, and summarize() or framesAdded() with any add, need the
/// caller's exclusion.
/// Images are row-major without padding, `n` pixels; flows interleaved (u, v) floats, NaN where
/// undefined.
class Evaluation {
 public:
  /// The class table gives the names and which classes are scored; void classes (for instance
  /// AP) are those without class_eval.
  explicit Evaluation(const ClassTable& classes, EvaluationOptions options = {});

  /// Semantic class ids of ground truth and prediction. Throws std::invalid_argument on null
  /// pointers.
  void addSemantic(const std::string& condition, const uint8_t* gt, const uint8_t* pred, size_t n);
  /// Ground-truth instance ids (0 = none) and class ids, and the predicted instances (full-frame
  /// masks of n pixels). Throws std::invalid_argument if a mask has another size.
  void addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes, size_t n,
                    const std::vector<PredictedInstance>& predictions);
  /// The same for masks given in boxes of a width x height frame. Throws std::invalid_argument if
  /// a box leaves the frame or a non-empty box has no mask.
  void addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes, uint32_t width,
                    uint32_t height, const std::vector<BoxedInstance>& predictions);
  /// Dense flow of the same frame pair; `visible` (non-zero = visible in the second frame) selects
  /// the non-occluded pixels, and may be null (then "noc" equals "all").
  void addFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible, const float* pred_uv,
               size_t n);
  /// Sparse flow of the same frame pair: each vector is scored against the ground truth at the
  /// pixel nearest its point; points outside the w x h image are not scored. Returns how many
  /// vectors were scored (ground truth defined there).
  size_t addSparseFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible, uint32_t width,
                       uint32_t height, const std::vector<SparseFlowVector>& flow);
  /// One pose pair (camera to world: ground truth and estimate, each in its own world frame).
  /// Poses of one condition with increasing frame numbers form one trajectory; another condition
  /// or a frame number that does not increase starts a new one.
  void addPose(const std::string& condition, uint64_t frame_number, const Eigen::Isometry3d& gt,
               const Eigen::Isometry3d& estimate);

  /// Every number, per condition and over all.
  EvaluationSummary summarize() const;
  /// Frames added so far, over every metric (a pose counts as a frame).
  uint64_t framesAdded() const;

 private:
  struct Trajectory {
    std::vector<Eigen::Isometry3d> gt, est;
    uint64_t last_frame = 0;
  };
  struct FlowState {
    FlowErrorAccumulator all, noc;
    uint64_t frames = 0, vectors = 0;
  };
  /// Adds one frame's overlaps to its condition's accumulator and to the overall one.
  void addInstanceOverlaps(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                           uint32_t width, uint32_t height, const std::vector<BoxedInstance>& predictions);
  void fillOdometry(const std::vector<const Trajectory*>& trajectories, ConditionSummary& out) const;

  ClassTable classes_;
  EvaluationOptions options_;
  std::vector<bool> semantic_eval_, instance_eval_, void_class_;
  // One map per metric (condition -> state), so that metrics can be added concurrently.
  std::map<std::string, std::pair<SemanticConfusion, uint64_t>> semantic_;  // confusion, frames
  std::map<std::string, std::pair<InstanceApAccumulator, uint64_t>> instances_;
  std::optional<InstanceApAccumulator> all_instances_;  // AP does not merge: frames are also added here
  std::map<std::string, FlowState> flow_, sparse_;
  std::map<std::string, std::vector<Trajectory>> trajectories_;
  std::string last_pose_condition_;
  uint64_t semantic_frames_ = 0, instance_frames_ = 0, flow_frames_ = 0, sparse_frames_ = 0, poses_ = 0;
};

}  // namespace viper
