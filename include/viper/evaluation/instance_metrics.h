// Instance segmentation scores with the Cityscapes protocol, as VIPER reports them:
// region AP averaged over IoU thresholds 0.50:0.05:0.95, and AP at 50%.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace viper {

/// One predicted instance: a full-frame mask (non-zero = inside), its class and confidence.
struct PredictedInstance {
  int class_id = 0;
  double score = 0.0;
  std::vector<uint8_t> mask;
};

/// A predicted instance whose mask covers a box of the frame (cheaper than a full-frame mask).
struct BoxedInstance {
  int class_id = 0;
  double score = 0.0;
  uint32_t x0 = 0, y0 = 0;          ///< the box's top-left pixel in the frame
  uint32_t width = 0, height = 0;   ///< the box's size (pixels)
  const uint8_t* mask = nullptr;    ///< width x height bytes, row-major, non-zero = inside (not owned)
};

/// What one frame contributes to instance AP: its ground-truth instances and every prediction's
/// overlaps with them. Made by InstanceApAccumulator::overlaps(); one frame's overlaps can be
/// added to several accumulators (e.g. one per condition and one over all).
struct InstanceOverlaps {
  /// A ground-truth instance: its id, its majority class (of equal counts the lower class id) and
  /// its size in pixels. Or a group region (`group`, id 0): every pixel of one instance class
  /// without an instance id (Cityscapes' "cargroup"), never matched, ignored by its class's
  /// predictions.
  struct GroundTruth {
    int32_t id = 0;
    int class_id = 0;
    uint64_t pixels = 0;
    bool group = false;
  };
  /// A prediction: its pixels, those of them on void ground truth, and its intersection with each
  /// ground-truth instance it meets (index into `ground_truth` in ascending order, pixels > 0).
  struct Prediction {
    int class_id = 0;
    double score = 0.0;
    uint64_t pixels = 0, void_pixels = 0;
    std::vector<std::pair<uint32_t, uint64_t>> with_gt;
  };
  std::vector<GroundTruth> ground_truth;  ///< the groups (in descending class), then instances in ascending id
  std::vector<Prediction> predictions;    ///< in the order given
};

/// Accumulates matches over frames and computes average precision per class.
///
/// Protocol (cityscapesScripts `evalInstanceLevelSemanticLabeling.py`, docs/evaluate.md): a
/// prediction matches a ground-truth instance of its class when their IoU exceeds the threshold; of
/// several matches of one ground truth the best-scored is a true positive and the rest are false
/// positives; ground truth under `min_region_px` pixels and group regions (pixels of an evaluated
/// class without an instance id) are never matched; a prediction whose IoU with one of them exceeds
/// the threshold is dropped, and an unmatched prediction is a false positive unless more than the
/// threshold's share of it lies on void pixels, its class's group or small ground truth; AP is the
/// step-wise integral of the precision-recall curve closed by the point (recall 0, precision 1).
class InstanceApAccumulator {
 public:
  /// `evaluated[c]`: whether class c is scored (ClassTable::instanceEvalMask()); its pixels
  /// without an instance id are its group region.
  /// `void_class[c]`: whether ground-truth pixels of class c without an instance id (id <= 0) are
  /// void (ClassTable's classes with class_eval = 0); pixels of an instance are never void.
  InstanceApAccumulator(std::vector<bool> evaluated, std::vector<bool> void_class, int min_region_px = 100);

  /// Adds one frame. `gt_instance_ids`: per pixel instance id (0 = none), `gt_class_ids`: per pixel
  /// class id; an instance's class is the majority class of its pixels. Throws
  /// std::invalid_argument if a prediction's mask size differs from n.
  void add(const int32_t* gt_instance_ids, const uint8_t* gt_class_ids, size_t n,
           const std::vector<PredictedInstance>& predictions);
  /// The overlaps of one width x height frame (images as in add()) with predictions given in
  /// boxes, void counted with this accumulator's void classes. Reads each image and mask byte
  /// once. Throws std::invalid_argument on a null image, a box that leaves the frame or a
  /// non-empty box without a mask.
  InstanceOverlaps overlaps(const int32_t* gt_instance_ids, const uint8_t* gt_class_ids, uint32_t width,
                            uint32_t height, const std::vector<BoxedInstance>& predictions) const;
  /// Adds one frame's overlaps, made by an accumulator with the same void classes.
  void add(const InstanceOverlaps& frame);

  /// The IoU thresholds 0.50, 0.55, ..., 0.95.
  static const std::vector<double>& thresholds();
  /// AP of class c at threshold index t, in 0..1. 0 if the class has ground truth but no
  /// prediction; NaN if it has no ground truth.
  double ap(int c, size_t t) const;
  /// AP of class c averaged over the thresholds (NaN if the class has no ground truth).
  double classAp(int c) const;
  /// AP of class c at IoU 0.5.
  double classAp50(int c) const { return ap(c, 0); }
  /// Mean over evaluated classes and thresholds, ignoring NaN (Cityscapes `allAp`).
  double meanAp() const;
  /// Mean over evaluated classes at IoU 0.5 (Cityscapes `allAp50%`).
  double meanAp50() const;

 private:
  struct Curve {
    std::vector<double> scores;
    std::vector<uint8_t> is_true;
    uint64_t hard_false_negatives = 0;
  };
  std::vector<bool> evaluated_, void_class_;
  int min_region_px_;
  std::vector<std::vector<Curve>> curves_;  // [class][threshold]
  std::vector<bool> have_gt_, have_pred_;
};

}  // namespace viper
