// Semantic segmentation scores as VIPER reports them: IoU per evaluated class and their mean.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper {

/// Accumulates a confusion matrix over frames. Pixels whose ground-truth class is not evaluated
/// are ignored; a prediction of any class (evaluated or not) on an evaluated pixel counts.
class SemanticConfusion {
 public:
  /// `evaluated[c]` says whether class id c is scored (see ClassTable::semanticEvalMask()).
  explicit SemanticConfusion(std::vector<bool> evaluated);

  /// Adds one frame of `n` pixels of class ids. Ids >= the number of classes count as "other"
  /// (a wrong prediction; an ignored ground truth). Throws std::invalid_argument if a pointer is null.
  void add(const uint8_t* ground_truth, const uint8_t* prediction, size_t n);
  /// Adds the counts of another accumulator with the same class mask.
  void merge(const SemanticConfusion& other);

  /// Intersection over union of class c: TP / (TP + FP + FN). NaN if c is not evaluated or appears
  /// neither in ground truth nor prediction.
  double iou(int c) const;
  /// Mean of iou(c) over evaluated classes with a value: every class with a true positive, false
  /// positive or false negative, so a class predicted but absent from the ground truth counts as 0
  /// (cityscapesScripts `getScoreAverage`). NaN if there are none.
  double meanIou() const;
  /// Ground-truth pixels that were scored.
  uint64_t scoredPixels() const { return scored_; }
  size_t numClasses() const { return evaluated_.size(); }

 private:
  std::vector<bool> evaluated_;
  std::vector<uint64_t> tp_, fp_, fn_;
  uint64_t scored_ = 0;
};

}  // namespace viper
