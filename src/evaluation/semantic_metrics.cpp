#include "viper/evaluation/semantic_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {

SemanticConfusion::SemanticConfusion(std::vector<bool> evaluated)
    : evaluated_(std::move(evaluated)),
      tp_(evaluated_.size(), 0),
      fp_(evaluated_.size(), 0),
      fn_(evaluated_.size(), 0) {
  if (evaluated_.empty() || evaluated_.size() > 256)
    throw std::invalid_argument("SemanticConfusion: class mask must have 1..256 entries");
}

void SemanticConfusion::add(const uint8_t* gt, const uint8_t* pred, size_t n) {
  if (n > 0 && (gt == nullptr || pred == nullptr))
    throw std::invalid_argument("SemanticConfusion::add: null image");
  const size_t k = evaluated_.size();
  // Counts per (ground-truth row, prediction) with the per-pixel loop branch-free; ground truth of
  // ids >= k (ignored) shares one row. Pixel i goes to table i % 4, so that a run of one pair, most
  // of a frame, does not wait on the previous increment's store. The tables are small enough for
  // the cache with 32-bit counts, folded into the totals every kChunk pixels.
  constexpr size_t kTables = 4, kChunk = size_t{1} << 30;
  const size_t table = (k + 1) * 256;
  std::vector<uint32_t> hist(kTables * table, 0);
  uint32_t row[256];
  for (size_t g = 0; g < 256; ++g) row[g] = static_cast<uint32_t>(std::min(g, k) * 256);
  for (size_t start = 0; start < n; start += kChunk) {
    const size_t m = std::min(kChunk, n - start);
    const uint8_t* gc = gt + start;
    const uint8_t* pc = pred + start;
    uint32_t* h0 = hist.data();
    uint32_t* h1 = h0 + table;
    uint32_t* h2 = h1 + table;
    uint32_t* h3 = h2 + table;
    size_t i = 0;
    for (; i + kTables <= m; i += kTables) {
      ++h0[row[gc[i]] + pc[i]];
      ++h1[row[gc[i + 1]] + pc[i + 1]];
      ++h2[row[gc[i + 2]] + pc[i + 2]];
      ++h3[row[gc[i + 3]] + pc[i + 3]];
    }
    for (; i < m; ++i) ++h0[row[gc[i]] + pc[i]];
    for (size_t g = 0; g < k; ++g) {
      if (!evaluated_[g]) continue;
      for (size_t p = 0; p < 256; ++p) {
        const size_t bin = g * 256 + p;
        const uint64_t count = uint64_t{h0[bin]} + h1[bin] + h2[bin] + h3[bin];
        if (count == 0) continue;
        scored_ += count;
        if (p == g) {
          tp_[g] += count;
        } else {
          fn_[g] += count;
          if (p < k) fp_[p] += count;
        }
      }
    }
    std::fill(hist.begin(), hist.end(), 0u);
  }
}

void SemanticConfusion::merge(const SemanticConfusion& other) {
  if (other.evaluated_ != evaluated_) throw std::invalid_argument("SemanticConfusion::merge: class masks differ");
  for (size_t c = 0; c < evaluated_.size(); ++c) {
    tp_[c] += other.tp_[c];
    fp_[c] += other.fp_[c];
    fn_[c] += other.fn_[c];
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
    const double v = iou(static_cast<int>(c));
    if (std::isnan(v)) continue;
    sum += v;
    ++n;
  }
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : sum / n;
}

}  // namespace viper
