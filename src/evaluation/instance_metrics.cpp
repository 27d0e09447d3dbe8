#include "viper/evaluation/instance_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace viper {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

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
  // The curve's artificial end point: precision 1 at recall 0 (cityscapesScripts), whatever the
  // precision at the top score. With every prediction tied at one score, the curve is this point
  // and the one of that score.
  precision.push_back(1.0);
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
  if (n >= std::numeric_limits<uint32_t>::max()) throw std::invalid_argument("InstanceApAccumulator::add: frame too large");
  // A full-frame mask is a box of one row of n pixels.
  std::vector<BoxedInstance> boxed(predictions.size());
  for (size_t p = 0; p < predictions.size(); ++p) {
    const auto& pred = predictions[p];
    if (pred.mask.size() != n)
      throw std::invalid_argument("InstanceApAccumulator::add: prediction " + std::to_string(p) + " mask has " +
                                  std::to_string(pred.mask.size()) + " pixels, frame has " + std::to_string(n));
    boxed[p].class_id = pred.class_id;
    boxed[p].score = pred.score;
    boxed[p].width = static_cast<uint32_t>(n), boxed[p].height = n > 0 ? 1 : 0;
    boxed[p].mask = pred.mask.data();
  }
  add(overlaps(gt_ids, gt_classes, static_cast<uint32_t>(n), n > 0 ? 1 : 0, boxed));
}

namespace {

// Pixels are visited in blocks: a block where the ground truth does not change (most of them) is
// counted at once, in loops the compiler vectorises; only blocks with an edge go pixel by pixel.
constexpr uint32_t kBlock = 32;

// Block helpers, each a loop of its own: inside the pixel loops GCC unrolls them instead of
// vectorising them.
uint32_t orBytes(const uint8_t* __restrict m) {
  uint32_t a = 0;
  for (uint32_t j = 0; j < kBlock; ++j) a |= m[j];
  return a;
}
uint32_t countNonZero(const uint8_t* __restrict m) {
  uint32_t c = 0;
  for (uint32_t j = 0; j < kBlock; ++j) c += m[j] != 0;
  return c;
}
// Non-zero where some pixel of the block differs from (id, cls).
uint32_t differs(const int32_t* __restrict ids, const uint8_t* __restrict cls, int32_t id, uint8_t c) {
  uint32_t d = 0;
  for (uint32_t j = 0; j < kBlock; ++j) d |= static_cast<uint32_t>(ids[j] ^ id) | static_cast<uint32_t>(cls[j] ^ c);
  return d;
}

// Dense indices of the ground-truth ids of a frame (ids > 0), looked up only where the id changes.
class DenseIds {
 public:
  uint32_t index(int32_t id) {
    if (id == last_id_) return last_index_;
    const auto it = index_.emplace(id, static_cast<uint32_t>(index_.size())).first;
    last_id_ = id, last_index_ = it->second;
    return last_index_;
  }
  // Renumbers the indices in ascending id; returns (id, former index) in that order.
  std::vector<std::pair<int32_t, uint32_t>> sortById() {
    std::vector<std::pair<int32_t, uint32_t>> ids(index_.begin(), index_.end());
    std::sort(ids.begin(), ids.end());
    for (uint32_t i = 0; i < ids.size(); ++i) index_[ids[i].first] = i;
    last_id_ = 0;
    return ids;
  }

 private:
  std::unordered_map<int32_t, uint32_t> index_;
  int32_t last_id_ = 0;  // never looked up
  uint32_t last_index_ = 0;
};

}  // namespace

InstanceOverlaps InstanceApAccumulator::overlaps(const int32_t* gt_ids, const uint8_t* gt_classes, uint32_t width,
                                                 uint32_t height, const std::vector<BoxedInstance>& predictions) const {
  const size_t n = static_cast<size_t>(width) * height;
  if (n > 0 && (gt_ids == nullptr || gt_classes == nullptr))
    throw std::invalid_argument("InstanceApAccumulator::overlaps: null ground truth image");
  for (size_t p = 0; p < predictions.size(); ++p) {
    const BoxedInstance& b = predictions[p];
    if (static_cast<uint64_t>(b.x0) + b.width > width || static_cast<uint64_t>(b.y0) + b.height > height)
      throw std::invalid_argument("InstanceApAccumulator::overlaps: prediction " + std::to_string(p) +
                                  " leaves the frame");
    if (b.mask == nullptr && b.width > 0 && b.height > 0)
      throw std::invalid_argument("InstanceApAccumulator::overlaps: prediction " + std::to_string(p) + " has no mask");
  }
  // Cityscapes reads void and groups from the instance-id image: a pixel of an instance is never
  // void; one without an instance id is void if its class is not scored, and belongs to its
  // class's group region if that class is an instance class.
  uint8_t is_void[256] = {}, is_group[256] = {};
  for (size_t c = 0; c < void_class_.size(); ++c) is_void[c] = void_class_[c], is_group[c] = evaluated_[c];
  // Key of a pixel's region: its instance id, -1 - class for a group, 0 for none.
  auto key = [&](int32_t id, uint8_t cls) -> int32_t { return id > 0 ? id : is_group[cls] ? -1 - cls : 0; };

  // Ground truth: runs of one (id, class) are votes for the instance's class.
  DenseIds dense;
  std::vector<std::vector<std::pair<int, uint64_t>>> votes;  // per dense index: (class, pixels)
  auto vote = [&](int32_t id, uint8_t cls, uint64_t count) {
    const int32_t k = key(id, cls);
    if (k == 0 || count == 0) return;
    const uint32_t d = dense.index(k);
    if (d == votes.size()) votes.emplace_back();
    for (auto& v : votes[d])
      if (v.first == cls) {
        v.second += count;
        return;
      }
    votes[d].emplace_back(cls, count);
  };
  int32_t run_id = n > 0 ? gt_ids[0] : 0;
  uint8_t run_cls = n > 0 ? gt_classes[0] : 0;
  uint64_t run = 0;
  for (size_t i = 0; i < n;) {
    if (i + kBlock <= n) {
      if (differs(gt_ids + i, gt_classes + i, run_id, run_cls) == 0) {
        run += kBlock, i += kBlock;
        continue;
      }
    }
    for (const size_t end = std::min(n, i + kBlock); i < end; ++i) {
      if (gt_ids[i] != run_id || gt_classes[i] != run_cls) {
        vote(run_id, run_cls, run);
        run_id = gt_ids[i], run_cls = gt_classes[i], run = 0;
      }
      ++run;
    }
  }
  vote(run_id, run_cls, run);

  InstanceOverlaps out;
  const auto sorted = dense.sortById();
  const size_t num_gt = sorted.size();
  out.ground_truth.resize(num_gt);
  for (size_t g = 0; g < num_gt; ++g) {
    InstanceOverlaps::GroundTruth& gt = out.ground_truth[g];
    gt.id = std::max(sorted[g].first, 0);
    gt.group = sorted[g].first < 0;
    uint64_t best = 0;
    for (const auto& v : votes[sorted[g].second]) {
      gt.pixels += v.second;
      if (v.second > best || (v.second == best && v.first < gt.class_id)) best = v.second, gt.class_id = v.first;
    }
  }

  // Predictions: pixels per (instance slot, void) in a small table; slot 0 is no instance.
  std::vector<uint64_t> counts(2 * (num_gt + 1), 0);
  auto slot = [&](int32_t id, uint8_t cls) {
    const int32_t k = key(id, cls);
    return 2 * static_cast<size_t>(k != 0 ? dense.index(k) + 1 : 0) + (id <= 0 && is_void[cls]);
  };
  out.predictions.resize(predictions.size());
  for (size_t p = 0; p < predictions.size(); ++p) {
    const BoxedInstance& b = predictions[p];
    const uint32_t bw = b.width, bh = b.height;
    for (uint32_t y = 0; y < bh; ++y) {
      const uint8_t* m = b.mask + static_cast<size_t>(y) * bw;
      const size_t row = static_cast<size_t>(b.y0 + y) * width + b.x0;
      const int32_t* ids = gt_ids + row;
      const uint8_t* cls = gt_classes + row;
      for (uint32_t x = 0; x < bw;) {
        if (x + kBlock <= bw) {
          if (orBytes(m + x) == 0) {
            x += kBlock;
            continue;
          }
          if (differs(ids + x, cls + x, ids[x], cls[x]) == 0) {
            counts[slot(ids[x], cls[x])] += countNonZero(m + x);
            x += kBlock;
            continue;
          }
        }
        for (const uint32_t end = std::min(bw, x + kBlock); x < end; ++x)
          if (m[x]) ++counts[slot(ids[x], cls[x])];
      }
    }
    InstanceOverlaps::Prediction& pred = out.predictions[p];
    pred.class_id = b.class_id;
    pred.score = b.score;
    for (size_t g = 0; g <= num_gt; ++g) {
      const uint64_t inside = counts[2 * g] + counts[2 * g + 1];
      pred.pixels += inside;
      pred.void_pixels += counts[2 * g + 1];
      if (g > 0 && inside > 0) pred.with_gt.emplace_back(static_cast<uint32_t>(g - 1), inside);
      counts[2 * g] = counts[2 * g + 1] = 0;
    }
  }
  return out;
}

void InstanceApAccumulator::add(const InstanceOverlaps& frame) {
  const size_t k = evaluated_.size();
  const auto& gts = frame.ground_truth;
  const auto& preds = frame.predictions;
  std::vector<uint8_t> ignored(gts.size());
  for (size_t g = 0; g < gts.size(); ++g) ignored[g] = gts[g].pixels < static_cast<uint64_t>(min_region_px_);
  std::vector<int32_t> column(gts.size());  // a ground truth's column in the class's IoU table, or -1
  for (size_t c = 0; c < k; ++c) {
    if (!evaluated_[c]) continue;
    std::vector<uint32_t> class_gts;
    std::fill(column.begin(), column.end(), -1);
    for (uint32_t g = 0; g < gts.size(); ++g)
      if (gts[g].class_id == static_cast<int>(c) && !ignored[g] && !gts[g].group) {
        column[g] = static_cast<int32_t>(class_gts.size());
        class_gts.push_back(g);
      }
    std::vector<size_t> class_preds;
    for (size_t p = 0; p < preds.size(); ++p)
      if (preds[p].class_id == static_cast<int>(c) && preds[p].pixels > 0) class_preds.push_back(p);
    if (!class_gts.empty()) have_gt_[c] = true;
    if (!class_preds.empty()) have_pred_[c] = true;
    if (class_gts.empty() && class_preds.empty()) continue;
    // IoU of each (prediction, ground truth) pair of the class; -1 where they do not meet.
    const size_t cols = class_gts.size();
    std::vector<double> pair_iou(class_preds.size() * cols, -1.0);
    for (size_t q = 0; q < class_preds.size(); ++q) {
      const auto& pred = preds[class_preds[q]];
      for (const auto& w : pred.with_gt)
        if (column[w.first] >= 0) pair_iou[q * cols + column[w.first]] = iou(w.second, gts[w.first].pixels, pred.pixels);
    }

    for (size_t t = 0; t < thresholds().size(); ++t) {
      const double th = thresholds()[t];
      Curve& curve = curves_[c][t];
      for (size_t col = 0; col < cols; ++col) {
        bool matched = false;
        double best = 0.0;
        for (size_t q = 0; q < class_preds.size(); ++q) {
          if (pair_iou[q * cols + col] <= th) continue;
          const double s = preds[class_preds[q]].score;
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
        const auto& pred = preds[p];
        bool found = false;
        uint64_t ignore = pred.void_pixels;
        for (const auto& w : pred.with_gt) {
          const InstanceOverlaps::GroundTruth& g = gts[w.first];
          if (g.class_id != static_cast<int>(c)) continue;  // predictions only meet their own class
          if (iou(w.second, g.pixels, pred.pixels) > th) {
            found = true;  // also when that ground truth is a group or too small to count
            break;
          }
          // A small group counts twice, as cityscapesScripts does.
          if (g.group) ignore += w.second;
          if (ignored[w.first]) ignore += w.second;
        }
        if (!found && static_cast<double>(ignore) / pred.pixels <= th) {
          curve.scores.push_back(pred.score);
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
