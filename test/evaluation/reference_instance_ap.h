// Cityscapes instance AP counted pixel by pixel with maps, step by step as cityscapesScripts'
// evalInstanceLevelSemanticLabeling.py does it (assignGt2Preds, evaluateMatches): the reference
// that test_metrics_equivalence.cpp holds the accumulator's kernels to. Written apart from the
// kernel: void and groups come from the instance ids per pixel, the precision-recall curve is built
// as numpy does it (ascending sort, first index of each unique score, cumulative sums, the
// artificial point (recall 0, precision 1), step widths by a convolution with [-0.5, 0, 0.5]).
#pragma once

#include "viper/evaluation/instance_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <vector>

namespace viper {

class ReferenceAp {
 public:
  ReferenceAp(std::vector<bool> evaluated, std::vector<bool> void_class, int min_region_px)
      : evaluated_(std::move(evaluated)), void_class_(std::move(void_class)), min_region_px_(min_region_px) {
    examples_.assign(evaluated_.size(), std::vector<Examples>(InstanceApAccumulator::thresholds().size()));
    have_gt_.assign(evaluated_.size(), false);
    have_pred_.assign(evaluated_.size(), false);
  }

  void add(const int32_t* gt_ids, const uint8_t* gt_classes, size_t n, const std::vector<PredictedInstance>& preds) {
    const size_t k = evaluated_.size();
    // Regions: instances by id (> 0), groups by -1 - class (no id, an evaluated class).
    auto region = [&](size_t i) -> int64_t {
      if (gt_ids[i] > 0) return gt_ids[i];
      return gt_classes[i] < k && evaluated_[gt_classes[i]] ? -1 - int64_t{gt_classes[i]} : 0;
    };
    std::map<int64_t, std::map<int, uint64_t>> votes;
    for (size_t i = 0; i < n; ++i)
      if (region(i) != 0) ++votes[region(i)][gt_classes[i]];
    struct Gt {
      int class_id = 0;
      uint64_t pixels = 0;
      bool group = false, small = false;
    };
    std::map<int64_t, Gt> gts;
    for (const auto& v : votes) {
      Gt g;
      uint64_t best = 0;
      for (const auto& cv : v.second) {
        g.pixels += cv.second;
        if (cv.second > best) best = cv.second, g.class_id = cv.first;
      }
      g.group = v.first < 0;
      g.small = g.pixels < static_cast<uint64_t>(min_region_px_);
      gts[v.first] = g;
    }
    struct Ov {
      uint64_t pixels = 0, void_pixels = 0;
      std::map<int64_t, uint64_t> with_gt;
    };
    std::vector<Ov> ov(preds.size());
    for (size_t p = 0; p < preds.size(); ++p)
      for (size_t i = 0; i < n; ++i) {
        if (!preds[p].mask[i]) continue;
        ++ov[p].pixels;
        if (gt_ids[i] <= 0 && gt_classes[i] < k && void_class_[gt_classes[i]]) ++ov[p].void_pixels;
        if (region(i) != 0) ++ov[p].with_gt[region(i)];
      }
    auto iou = [](uint64_t inter, uint64_t a, uint64_t b) { return static_cast<double>(inter) / (a + b - inter); };
    for (size_t c = 0; c < k; ++c) {
      if (!evaluated_[c]) continue;
      std::vector<int64_t> class_gts;
      for (const auto& g : gts)
        if (g.second.class_id == static_cast<int>(c) && !g.second.small && !g.second.group) class_gts.push_back(g.first);
      std::vector<size_t> class_preds;
      for (size_t p = 0; p < preds.size(); ++p)
        if (preds[p].class_id == static_cast<int>(c) && ov[p].pixels > 0) class_preds.push_back(p);
      if (!class_gts.empty()) have_gt_[c] = true;
      if (!class_preds.empty()) have_pred_[c] = true;
      for (size_t t = 0; t < InstanceApAccumulator::thresholds().size(); ++t) {
        const double th = InstanceApAccumulator::thresholds()[t];
        Examples& y = examples_[c][t];
        // Every prediction above the threshold with a ground truth: the best-scored is its true
        // positive, every other one a false positive at its own score.
        for (int64_t gid : class_gts) {
          std::vector<double> matched;
          for (size_t p : class_preds) {
            auto it = ov[p].with_gt.find(gid);
            if (it != ov[p].with_gt.end() && iou(it->second, gts[gid].pixels, ov[p].pixels) > th)
              matched.push_back(preds[p].score);
          }
          if (matched.empty()) {
            ++y.hard_fns;
            continue;
          }
          std::sort(matched.begin(), matched.end());
          for (size_t m = 0; m < matched.size(); ++m) {
            y.score.push_back(matched[m]);
            y.truth.push_back(m + 1 == matched.size() ? 1.0 : 0.0);
          }
        }
        for (size_t p : class_preds) {
          bool found = false;
          for (const auto& w : ov[p].with_gt) {
            const Gt& g = gts[w.first];
            if (g.class_id == static_cast<int>(c) && iou(w.second, g.pixels, ov[p].pixels) > th) found = true;
          }
          if (found) continue;
          uint64_t ignore = ov[p].void_pixels;
          for (const auto& w : ov[p].with_gt) {
            const Gt& g = gts[w.first];
            if (g.class_id != static_cast<int>(c)) continue;
            if (g.group) ignore += w.second;
            if (g.small) ignore += w.second;
          }
          if (static_cast<double>(ignore) / ov[p].pixels <= th) {
            y.score.push_back(preds[p].score);
            y.truth.push_back(0.0);
          }
        }
      }
    }
  }

  double ap(int c, size_t t) const {
    if (!evaluated_[c] || !have_gt_[c]) return std::nan("");
    if (!have_pred_[c]) return 0.0;
    const Examples& y = examples_[c][t];
    const size_t n = y.score.size();
    if (n == 0) return 0.0;  // cityscapesScripts fails here (the cumulative sum of nothing)
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return y.score[a] < y.score[b]; });
    std::vector<double> sorted(n), cumsum(n);
    for (size_t i = 0; i < n; ++i) {
      sorted[i] = y.score[order[i]];
      cumsum[i] = (i > 0 ? cumsum[i - 1] : 0.0) + y.truth[order[i]];
    }
    std::vector<size_t> unique_indices;
    for (size_t i = 0; i < n; ++i)
      if (i == 0 || sorted[i] != sorted[i - 1]) unique_indices.push_back(i);
    const double true_examples = cumsum[n - 1];
    cumsum.push_back(0.0);  // index -1 reads this zero
    const size_t points = unique_indices.size() + 1;
    std::vector<double> precision(points), recall(points);
    for (size_t r = 0; r < unique_indices.size(); ++r) {
      const size_t idx = unique_indices[r];
      const double below = cumsum[idx == 0 ? n : idx - 1];
      const double tp = true_examples - below, fp = static_cast<double>(n - idx) - tp;
      const double fn = below + static_cast<double>(y.hard_fns);
      precision[r] = tp / (tp + fp);
      recall[r] = tp / (tp + fn);
    }
    precision[points - 1] = 1.0, recall[points - 1] = 0.0;
    std::vector<double> padded;  // recall with its first value repeated before and 0 after
    padded.push_back(recall[0]);
    padded.insert(padded.end(), recall.begin(), recall.end());
    padded.push_back(0.0);
    double ap = 0.0;
    for (size_t i = 0; i < points; ++i) ap += precision[i] * (0.5 * padded[i] - 0.5 * padded[i + 2]);
    return ap;
  }

 private:
  struct Examples {  // cityscapesScripts' y_score, y_true and hardFns of one class and threshold
    std::vector<double> score, truth;
    uint64_t hard_fns = 0;
  };
  std::vector<bool> evaluated_, void_class_;
  int min_region_px_;
  std::vector<std::vector<Examples>> examples_;
  std::vector<bool> have_gt_, have_pred_;
};

}  // namespace viper
