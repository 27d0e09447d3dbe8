#include "viper/core/semantic_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {

SemanticConfusion::SemanticConfusion(std::vector<bool> evaluated)
    : evaluated_(std::move(evaluated)),
      tp_(evaluated_.size(), 0),
      fp_(evaluated_.size(), 0),
      fn_(evaluated_.size(), 0),
      gt_count_(evaluated_.size(), 0) {
  if (evaluated_.empty() || evaluated_.size() > 256)
    throw std::invalid_argument("SemanticConfusion: class mask must have 1..256 entries");
}

void SemanticConfusion::add(const uint8_t* gt, const uint8_t* pred, size_t n) {
  if (n > 0 && (gt == nullptr || pred == nullptr))
    throw std::invalid_argument("SemanticConfusion::add: null image");
  const size_t k = evaluated_.size();
  // A 256x256 histogram keeps the per-pixel loop branch-free; it is folded into TP/FP/FN after.
  std::vector<uint64_t> hist(256 * 256, 0);
  for (size_t i = 0; i < n; ++i) ++hist[(static_cast<size_t>(gt[i]) << 8) | pred[i]];
  for (size_t g = 0; g < k; ++g) {
    if (!evaluated_[g]) continue;
    for (size_t p = 0; p < 256; ++p) {
      const uint64_t count = hist[(g << 8) | p];
      if (count == 0) continue;
      scored_ += count;
      gt_count_[g] += count;
      if (p == g) {
        tp_[g] += count;
      } else {
        fn_[g] += count;
        if (p < k) fp_[p] += count;
      }
    }
  }
}

void SemanticConfusion::merge(const SemanticConfusion& other) {
  if (other.evaluated_ != evaluated_) throw std::invalid_argument("SemanticConfusion::merge: class masks differ");
  for (size_t c = 0; c < evaluated_.size(); ++c) {
    tp_[c] += other.tp_[c];
    fp_[c] += other.fp_[c];
    fn_[c] += other.fn_[c];
    gt_count_[c] += other.gt_count_[c];
  }
  scored_ += other.scored_;
}

double SemanticConfusion::iou(int c) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (c < 0 || static_cast<size_t>(c) >= evaluated_.size() || !evaluated_[c]) return nan;
  const uint64_t denom = tp_[c] + fp_[c] + fn_[c];
  return denom == 0 ? nan : static_cast<double>(tp_[c]) / static_cast<double>(denom);
}

double SemanticConfusion::meanIou() const {
  double sum = 0.0;
  int n = 0;
  for (size_t c = 0; c < evaluated_.size(); ++c) {
    if (!evaluated_[c] || gt_count_[c] == 0) continue;
    sum += iou(static_cast<int>(c));
    ++n;
  }
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : sum / n;
}

}  // namespace viper
