// The optimised metric kernels against simple reference implementations written here (the
// per-pixel std::map counting they replaced; for instance AP, cityscapesScripts' steps in
// reference_instance_ap.h), on random frames: the scores must be identical, not just close.
#include "viper/evaluation/flow_metrics.h"
#include "viper/evaluation/instance_metrics.h"
#include "viper/evaluation/semantic_metrics.h"
#include "reference_instance_ap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace viper {
namespace {

struct Rng {
  uint32_t state;
  uint32_t next(uint32_t k) { return (state = state * 1664525u + 1013904223u) / 256u % k; }
};

void expectSameAp(const ReferenceAp& ref, const InstanceApAccumulator& acc, const std::string& what) {
  for (int c = 0; c < 32; ++c)
    for (size_t t = 0; t < InstanceApAccumulator::thresholds().size(); ++t) {
      const double a = ref.ap(c, t), b = acc.ap(c, t);
      if (std::isnan(a)) {
        EXPECT_TRUE(std::isnan(b)) << what << " class " << c << " threshold " << t;
      } else {
        EXPECT_EQ(a, b) << what << " class " << c << " threshold " << t;
      }
    }
}

// Random frames whose widths straddle the kernels' 32-pixel blocks: rectangles of random ids
// (large, negative, repeated), classes that are scored, void, unknown (>= 32) or mixed inside one
// instance (majority ties), and boxed predictions of random masks, sizes, classes and tied scores.
TEST(InstanceApEquivalence, RandomFramesScoreAsThePerPixelMapReference) {
  std::vector<bool> evaluated(32, false), void_class(32, false);
  for (int c : {20, 24, 25, 26}) evaluated[c] = true;
  for (int c : {0, 1, 5}) void_class[c] = true;
  const uint8_t kClasses[] = {0, 1, 3, 20, 24, 25, 26, 40, 255};
  const int32_t kIds[] = {1, 2, 3, 7, 1000, 123456789, 2147483647, -5, 0};
  Rng rnd{42};
  for (int min_region : {0, 20, 100}) {
    ReferenceAp ref(evaluated, void_class, min_region);
    InstanceApAccumulator full(evaluated, void_class, min_region), boxed(evaluated, void_class, min_region);
    for (int frame = 0; frame < 40; ++frame) {
      const uint32_t w = std::vector<uint32_t>{1, 7, 31, 32, 33, 64, 97, 150}[rnd.next(8)], h = 1 + rnd.next(40);
      const size_t n = size_t(w) * h;
      std::vector<int32_t> ids(n, 0);
      std::vector<uint8_t> cls(n);
      for (auto& c : cls) c = kClasses[rnd.next(3)];
      struct Rect {
        uint32_t x0, y0, w, h;
        uint8_t c;
      };
      std::vector<Rect> rects;
      const int rect_count = static_cast<int>(rnd.next(12));
      for (int r = 0; r < rect_count; ++r) {
        const uint32_t rw = 1 + rnd.next(w), rh = 1 + rnd.next(h), x0 = rnd.next(w - rw + 1), y0 = rnd.next(h - rh + 1);
        const int32_t id = kIds[rnd.next(9)];
        const uint8_t c = kClasses[rnd.next(9)], other = kClasses[rnd.next(9)];
        rects.push_back({x0, y0, rw, rh, c});
        const bool mixed = rnd.next(3) == 0;
        for (uint32_t y = y0; y < y0 + rh; ++y)
          for (uint32_t x = x0; x < x0 + rw; ++x)
            ids[y * w + x] = id, cls[y * w + x] = mixed && (x + y) % 2 ? other : c;
      }
      std::vector<PredictedInstance> masks;
      std::vector<std::vector<uint8_t>> box_masks;
      std::vector<BoxedInstance> boxes;
      const int count = static_cast<int>(rnd.next(8));
      for (int k = 0; k < count; ++k) {
        BoxedInstance b;
        b.class_id = std::vector<int>{20, 24, 25, 26, 3, 40}[rnd.next(6)];
        b.score = 0.25 * rnd.next(5);
        b.width = rnd.next(w + 1), b.height = rnd.next(h + 1);
        b.x0 = rnd.next(w - b.width + 1), b.y0 = rnd.next(h - b.height + 1);
        uint32_t density = rnd.next(4);  // empty, sparse, dense, full
        if (!rects.empty() && rnd.next(2) == 0) {  // on a ground-truth rectangle (maybe occluded), mostly its class
          const Rect& r = rects[rnd.next(static_cast<uint32_t>(rects.size()))];
          b.x0 = r.x0, b.y0 = r.y0, b.width = r.w, b.height = r.h, density = 3;
          if (rnd.next(4) != 0) b.class_id = r.c;
        }
        box_masks.emplace_back(size_t(b.width) * b.height);
        for (auto& v : box_masks.back())
          v = density == 0 ? 0 : density == 3 ? 255 : rnd.next(density == 1 ? 8 : 2) == 0 ? 1 + rnd.next(255) : 0;
        boxes.push_back(b);
        PredictedInstance p;
        p.class_id = b.class_id, p.score = b.score;
        p.mask.assign(n, 0);
        for (uint32_t y = 0; y < b.height; ++y)
          for (uint32_t x = 0; x < b.width; ++x) p.mask[(b.y0 + y) * w + b.x0 + x] = box_masks.back()[y * b.width + x];
        masks.push_back(std::move(p));
      }
      for (size_t k = 0; k < boxes.size(); ++k) boxes[k].mask = box_masks[k].data();
      ref.add(ids.data(), cls.data(), n, masks);
      full.add(ids.data(), cls.data(), n, masks);
      boxed.add(boxed.overlaps(ids.data(), cls.data(), w, h, boxes));
    }
    expectSameAp(ref, full, "full-frame masks, min_region " + std::to_string(min_region));
    expectSameAp(ref, boxed, "boxed masks, min_region " + std::to_string(min_region));
    int scored = 0;
    for (int c : {20, 24, 25, 26})
      if (!std::isnan(full.classAp(c)) && full.classAp(c) > 0.0 && full.classAp(c) < 1.0) ++scored;
    EXPECT_GE(scored, 1) << "the random frames should give some AP strictly between 0 and 1";
  }
}

// A frame made of the 32-pixel blocks the kernel skips or counts at once, with an instance edge
// in the middle of a block, and a mask that starts inside a block.
TEST(InstanceApEquivalence, WholeBlocksAndEdgesInsideBlocks) {
  std::vector<bool> evaluated(32, false), void_class(32, false);
  evaluated[24] = true, void_class[0] = true;
  constexpr uint32_t w = 128, h = 4;
  std::vector<int32_t> ids(w * h, 0);
  std::vector<uint8_t> cls(w * h, 3);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 16; x < 80; ++x) ids[y * w + x] = 9, cls[y * w + x] = 24;
  for (uint32_t x = 100; x < 128; ++x) cls[x] = 0;  // void on the first row
  PredictedInstance p;
  p.class_id = 24, p.score = 0.5;
  p.mask.assign(w * h, 0);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 20; x < 120; ++x) p.mask[y * w + x] = 1;
  InstanceApAccumulator acc(evaluated, void_class, 10);
  const InstanceOverlaps o = acc.overlaps(ids.data(), cls.data(), w * h, 1, {BoxedInstance{24, 0.5, 0, 0, w * h, 1, p.mask.data()}});
  ASSERT_EQ(o.ground_truth.size(), 1u);
  EXPECT_EQ(o.ground_truth[0].id, 9);
  EXPECT_EQ(o.ground_truth[0].class_id, 24);
  EXPECT_EQ(o.ground_truth[0].pixels, 64u * h);
  ASSERT_EQ(o.predictions.size(), 1u);
  EXPECT_EQ(o.predictions[0].pixels, 100u * h);
  EXPECT_EQ(o.predictions[0].void_pixels, 20u);  // x 100..119 of the first row
  ASSERT_EQ(o.predictions[0].with_gt.size(), 1u);
  EXPECT_EQ(o.predictions[0].with_gt[0], std::make_pair(uint32_t{0}, uint64_t{60u * h}));
  ReferenceAp ref(evaluated, void_class, 10);
  ref.add(ids.data(), cls.data(), w * h, {p});
  acc.add(o);
  expectSameAp(ref, acc, "blocks");
}

// Flow errors added pixel by pixel with a hypot per outlier test (the accumulator's original
// implementation; the endpoint error as sqrt of the sum of squares, as the accumulator computes it,
// and also by hypot: the two sums must agree to 1e-12), read back through the same formulas as the
// accumulator's.
struct ReferenceFlow {
  uint64_t scored = 0, invalid = 0, outliers = 0;
  double wauc_sum = 0.0, epe_sum = 0.0, epe_hypot_sum = 0.0;
  uint64_t hist[500] = {};
  void add(const float* gt, const float* pred, const uint8_t* mask, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      const float gu = gt[2 * i], gv = gt[2 * i + 1];
      if (!std::isfinite(gu) || !std::isfinite(gv) || (mask != nullptr && mask[i] == 0)) continue;
      ++scored;
      const float pu = pred[2 * i], pv = pred[2 * i + 1];
      if (!std::isfinite(pu) || !std::isfinite(pv)) {
        ++invalid, ++outliers;
        continue;
      }
      const double du = static_cast<double>(pu) - gu, dv = static_cast<double>(pv) - gv;
      const double e = std::sqrt(du * du + dv * dv);
      epe_sum += e;
      epe_hypot_sum += std::hypot(du, dv);
      if (e < 5.0) {
        const double w = 1.0 - e / 5.0;
        wauc_sum += w * w;
        ++hist[static_cast<int>(e * (500 / 5.0))];
      }
      if (e > 3.0 && e > 0.05 * std::hypot(static_cast<double>(gu), static_cast<double>(gv))) ++outliers;
    }
  }
  void expectSame(const FlowErrorAccumulator& acc, const std::string& what) const {
    EXPECT_EQ(acc.scoredPixels(), scored) << what;
    EXPECT_EQ(acc.invalidPredictions(), invalid) << what;
    if (scored == 0) return;
    EXPECT_EQ(acc.wauc(), 100.0 * wauc_sum / scored) << what;
    EXPECT_EQ(acc.outlierPercent(), 100.0 * outliers / scored) << what;
    if (scored > invalid) {
      EXPECT_EQ(acc.averageEndpointError(), epe_sum / (scored - invalid)) << what;
      EXPECT_NEAR(acc.averageEndpointError(), epe_hypot_sum / (scored - invalid),
                  1e-12 * epe_hypot_sum / (scored - invalid)) << what << ": sqrt and hypot disagree";
    }
    uint64_t below = 0;
    for (int b = 0; b < 500; ++b) {
      EXPECT_EQ(acc.inlierPercent(0.01 * (b + 0.5)), 100.0 * below / scored) << what << " bin " << b;
      below += hist[b];
    }
    EXPECT_EQ(acc.inlierPercent(7.0), 100.0 * below / scored) << what;
  }
};

// Random flows with undefined ground truth and predictions, errors across the 3 and 5 px
// thresholds, and predictions right at KITTI's 5 % outlier margin.
TEST(FlowEquivalence, RandomFlowsScoreAsTheHypotPerPixelReference) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  Rng rnd{7};
  auto uniform = [&](float lo, float hi) { return lo + (hi - lo) * static_cast<float>(rnd.next(1u << 20)) / (1u << 20); };
  FlowErrorAccumulator all, noc, masked, unmasked;
  ReferenceFlow ref_all, ref_noc;
  for (int frame = 0; frame < 5; ++frame) {
    const size_t n = 1 + rnd.next(5000);
    std::vector<float> gt(2 * n), pred(2 * n);
    std::vector<uint8_t> mask(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t kind = rnd.next(20);
      float gu = uniform(-80, 80), gv = uniform(-80, 80);
      if (kind == 0) gu = nan;
      if (kind == 1) gv = inf;
      if (kind == 2) gu = static_cast<float>(rnd.next(200)), gv = 0.0f;  // integer, for exact margins
      float pu = gu + uniform(-6, 6), pv = gv + uniform(-6, 6);
      if (kind == 3) pv = nan;
      if (kind == 4) pu = -inf;
      if (kind == 5 || kind == 2) pu = gu * 1.05f, pv = gv * 1.05f;  // 5 % of the ground truth
      if (kind == 6) pu = gu + 3.0f, pv = gv;                        // exactly 3 px
      if (kind == 7) pu = gu, pv = gv + 5.0f;                        // exactly 5 px
      gt[2 * i] = gu, gt[2 * i + 1] = gv, pred[2 * i] = pu, pred[2 * i + 1] = pv;
      mask[i] = rnd.next(4) == 0 ? 0 : static_cast<uint8_t>(1 + rnd.next(255));
    }
    FlowErrorAccumulator::addBoth(all, noc, gt.data(), pred.data(), mask.data(), n);
    masked.add(gt.data(), pred.data(), mask.data(), n);
    unmasked.add(gt.data(), pred.data(), nullptr, n);
    ref_all.add(gt.data(), pred.data(), nullptr, n);
    ref_noc.add(gt.data(), pred.data(), mask.data(), n);
  }
  ref_all.expectSame(all, "addBoth, all");
  ref_noc.expectSame(noc, "addBoth, masked");
  ref_all.expectSame(unmasked, "add without mask");
  ref_noc.expectSame(masked, "add with mask");
  EXPECT_GT(ref_all.outliers, ref_all.invalid) << "some finite errors should be outliers";
}

// Random class images (runs and noise, ids past the table) against a confusion matrix counted
// pixel by pixel.
TEST(SemanticEquivalence, RandomFramesScoreAsThePerPixelConfusionReference) {
  Rng rnd{3};
  for (size_t k : {size_t{1}, size_t{5}, size_t{32}, size_t{256}}) {
    std::vector<bool> evaluated(k);
    for (size_t c = 0; c < k; ++c) evaluated[c] = rnd.next(4) != 0;
    SemanticConfusion acc(evaluated);
    std::vector<uint64_t> tp(k), fp(k), fn(k);
    uint64_t scored = 0;
    for (int frame = 0; frame < 4; ++frame) {
      const size_t n = rnd.next(20000);
      std::vector<uint8_t> gt(n), pred(n);
      uint8_t g = 0, p = 0;
      for (size_t i = 0; i < n; ++i) {
        if (rnd.next(40) == 0) g = static_cast<uint8_t>(rnd.next(rnd.next(2) ? static_cast<uint32_t>(k) + 1 : 256));
        if (rnd.next(40) == 0) p = rnd.next(2) ? g : static_cast<uint8_t>(rnd.next(256));
        gt[i] = g, pred[i] = rnd.next(10) == 0 ? static_cast<uint8_t>(rnd.next(static_cast<uint32_t>(k) + 2)) : p;
        if (g >= k || !evaluated[g]) continue;
        ++scored;
        if (pred[i] == g) {
          ++tp[g];
        } else {
          ++fn[g];
          if (pred[i] < k) ++fp[pred[i]];
        }
      }
      acc.add(gt.data(), pred.data(), n);
    }
    EXPECT_EQ(acc.scoredPixels(), scored) << k;
    double sum = 0.0;
    int present = 0;
    for (size_t c = 0; c < k; ++c) {
      const uint64_t denom = tp[c] + fp[c] + fn[c];
      const double iou = evaluated[c] && denom > 0 ? static_cast<double>(tp[c]) / static_cast<double>(denom) : std::nan("");
      if (std::isnan(iou)) {
        EXPECT_TRUE(std::isnan(acc.iou(static_cast<int>(c)))) << k << " class " << c;
      } else {
        EXPECT_EQ(acc.iou(static_cast<int>(c)), iou) << k << " class " << c;
      }
      if (!std::isnan(iou)) sum += iou, ++present;  // cityscapesScripts: every class with a value
    }
    if (present > 0) {
      EXPECT_EQ(acc.meanIou(), sum / present) << k;
    } else {
      EXPECT_TRUE(std::isnan(acc.meanIou())) << k;
    }
  }
}

}  // namespace
}  // namespace viper
