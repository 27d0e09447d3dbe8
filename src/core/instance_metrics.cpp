#include "viper/core/instance_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

namespace viper {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

struct GtInstance {
  int class_id = 0;
  uint64_t pixels = 0;
  bool ignored = false;  // under the minimum region size
};

struct PredOverlaps {
  uint64_t pixels = 0, void_pixels = 0;
  std::map<int32_t, uint64_t> with_gt;  // gt instance id -> intersection
};

double iou(uint64_t inter, uint64_t a, uint64_t b) { return static_cast<double>(inter) / (a + b - inter); }

// Step-wise integral of the precision-recall curve, as cityscapesScripts computes it.
double averagePrecision(const std::vector<double>& scores, const std::vector<uint8_t>& is_true,
                        uint64_t hard_fns) {
  const size_t n = scores.size();
  if (n == 0) return 0.0;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return scores[a] < scores[b]; });
  std::vector<double> cumsum(n + 1, 0.0);  // cumsum[i] = trues among the i lowest scores
  for (size_t i = 0; i < n; ++i) cumsum[i + 1] = cumsum[i] + is_true[order[i]];
  const double total_true = cumsum[n];
  std::vector<double> precision, recall;
  for (size_t i = 0; i < n; ++i) {
    if (i > 0 && scores[order[i]] == scores[order[i - 1]]) continue;  // first index of each unique score
    const double tp = total_true - cumsum[i];
    const double fp = static_cast<double>(n - i) - tp;
    const double fn = cumsum[i] + hard_fns;
    precision.push_back(tp / (tp + fp));
    recall.push_back(tp + fn > 0 ? tp / (tp + fn) : 0.0);
  }
  precision.push_back(precision.back());
  recall.push_back(0.0);
  double ap = 0.0;
  const size_t m = recall.size();
  for (size_t i = 0; i < m; ++i) {
    const double before = i == 0 ? recall[0] : recall[i - 1];
    const double after = i + 1 < m ? recall[i + 1] : 0.0;
    ap += precision[i] * 0.5 * (before - after);
  }
  return ap;
}

}  // namespace

InstanceApAccumulator::InstanceApAccumulator(std::vector<bool> evaluated, std::vector<bool> void_class,
                                             int min_region_px)
    : evaluated_(std::move(evaluated)), void_class_(std::move(void_class)), min_region_px_(min_region_px) {
  if (evaluated_.empty() || evaluated_.size() > 256 || void_class_.size() != evaluated_.size())
    throw std::invalid_argument("InstanceApAccumulator: class masks must have the same size, 1..256");
  curves_.assign(evaluated_.size(), std::vector<Curve>(thresholds().size()));
  have_gt_.assign(evaluated_.size(), false);
  have_pred_.assign(evaluated_.size(), false);
}

const std::vector<double>& InstanceApAccumulator::thresholds() {
  static const std::vector<double> t = {0.50, 0.55, 0.60, 0.65, 0.70, 0.75, 0.80, 0.85, 0.90, 0.95};
  return t;
}

void InstanceApAccumulator::add(const int32_t* gt_ids, const uint8_t* gt_classes, size_t n,
                                const std::vector<PredictedInstance>& predictions) {
  if (n > 0 && (gt_ids == nullptr || gt_classes == nullptr))
    throw std::invalid_argument("InstanceApAccumulator::add: null ground truth image");
  const size_t k = evaluated_.size();
  // Ground-truth instances: pixel counts and majority class.
  std::map<int32_t, std::map<int, uint64_t>> votes;
  for (size_t i = 0; i < n; ++i)
    if (gt_ids[i] > 0) ++votes[gt_ids[i]][gt_classes[i]];
  std::map<int32_t, GtInstance> gts;
  for (const auto& v : votes) {
    GtInstance g;
    uint64_t best = 0;
    for (const auto& cv : v.second) {
      g.pixels += cv.second;
      if (cv.second > best) best = cv.second, g.class_id = cv.first;
    }
    g.ignored = g.pixels < static_cast<uint64_t>(min_region_px_);
    gts[v.first] = g;
  }
  // Overlaps of every prediction with ground truth instances and void.
  std::vector<PredOverlaps> ov(predictions.size());
  for (size_t p = 0; p < predictions.size(); ++p) {
    const auto& pred = predictions[p];
    if (pred.mask.size() != n)
      throw std::invalid_argument("InstanceApAccumulator::add: prediction " + std::to_string(p) + " mask has " +
                                  std::to_string(pred.mask.size()) + " pixels, frame has " + std::to_string(n));
    for (size_t i = 0; i < n; ++i) {
      if (!pred.mask[i]) continue;
      ++ov[p].pixels;
      if (gt_classes[i] < k && void_class_[gt_classes[i]]) ++ov[p].void_pixels;
      if (gt_ids[i] > 0) ++ov[p].with_gt[gt_ids[i]];
    }
  }
  for (size_t c = 0; c < k; ++c) {
    if (!evaluated_[c]) continue;
    std::vector<int32_t> class_gts;
    for (const auto& g : gts)
      if (g.second.class_id == static_cast<int>(c) && !g.second.ignored) class_gts.push_back(g.first);
    std::vector<size_t> class_preds;
    for (size_t p = 0; p < predictions.size(); ++p)
      if (predictions[p].class_id == static_cast<int>(c) && ov[p].pixels > 0) class_preds.push_back(p);
    if (!class_gts.empty()) have_gt_[c] = true;
    if (!class_preds.empty()) have_pred_[c] = true;

    for (size_t t = 0; t < thresholds().size(); ++t) {
      const double th = thresholds()[t];
      Curve& curve = curves_[c][t];
      for (int32_t gid : class_gts) {
        const GtInstance& g = gts[gid];
        bool matched = false;
        double best = 0.0;
        for (size_t p : class_preds) {
          auto it = ov[p].with_gt.find(gid);
          if (it == ov[p].with_gt.end() || iou(it->second, g.pixels, ov[p].pixels) <= th) continue;
          const double s = predictions[p].score;
          if (matched) {  // the lower-scored of two matches is a false positive
            curve.scores.push_back(std::min(best, s));
            curve.is_true.push_back(0);
            best = std::max(best, s);
          } else {
            matched = true;
            best = s;
          }
        }
        if (matched) {
          curve.scores.push_back(best);
          curve.is_true.push_back(1);
        } else {
          ++curve.hard_false_negatives;
        }
      }
      for (size_t p : class_preds) {
        bool found = false;
        uint64_t ignore = ov[p].void_pixels;
        for (const auto& w : ov[p].with_gt) {
          const GtInstance& g = gts[w.first];
          if (g.class_id != static_cast<int>(c)) continue;  // predictions only meet their own class
          if (iou(w.second, g.pixels, ov[p].pixels) > th) {
            found = true;  // also when that ground truth is too small to count
            break;
          }
          if (g.ignored) ignore += w.second;
        }
        if (!found && static_cast<double>(ignore) / ov[p].pixels <= th) {
          curve.scores.push_back(predictions[p].score);
          curve.is_true.push_back(0);
        }
      }
    }
  }
}

double InstanceApAccumulator::ap(int c, size_t t) const {
  if (c < 0 || static_cast<size_t>(c) >= evaluated_.size() || !evaluated_[c] || t >= thresholds().size() ||
      !have_gt_[c])
    return kNaN;
  if (!have_pred_[c]) return 0.0;
  const Curve& curve = curves_[c][t];
  return averagePrecision(curve.scores, curve.is_true, curve.hard_false_negatives);
}

double InstanceApAccumulator::classAp(int c) const {
  double sum = 0.0;
  for (size_t t = 0; t < thresholds().size(); ++t) sum += ap(c, t);
  return sum / thresholds().size();
}

double InstanceApAccumulator::meanAp() const {
  double sum = 0.0;
  int n = 0;
  for (size_t c = 0; c < evaluated_.size(); ++c)
    for (size_t t = 0; t < thresholds().size(); ++t) {
      const double a = ap(static_cast<int>(c), t);
      if (!std::isnan(a)) sum += a, ++n;
    }
  return n == 0 ? kNaN : sum / n;
}

double InstanceApAccumulator::meanAp50() const {
  double sum = 0.0;
  int n = 0;
  for (size_t c = 0; c < evaluated_.size(); ++c) {
    const double a = ap(static_cast<int>(c), 0);
    if (!std::isnan(a)) sum += a, ++n;
  }
  return n == 0 ? kNaN : sum / n;
}

}  // namespace viper
