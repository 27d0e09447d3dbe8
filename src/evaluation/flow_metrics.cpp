#include "viper/evaluation/flow_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {

namespace {

// KITTI's outlier test, e > 3 px and e > 5 % of hypot(gu, gv), without calling hypot where the
// answer is clear: the squares of float components are exact in double, so sqrt of their sum is
// within 2 ulp of hypot, far inside the margin; only errors at the margin ask hypot itself.
bool isOutlier(double e, float gu, float gv) {
  const double limit = 0.05 * std::sqrt(static_cast<double>(gu) * gu + static_cast<double>(gv) * gv);
  const bool clear = e > limit * (1.0 + 1e-12) || e < limit * (1.0 - 1e-12);
  if (__builtin_expect(clear, 1)) return e > 3.0 && e > limit;
  return e > 3.0 && e > 0.05 * std::hypot(static_cast<double>(gu), static_cast<double>(gv));
}

// WaucMode::kSampled: the first threshold i/20 px (i = 1..100) that an error is within, as i - 1;
// 100 for none. Exact at the thresholds (e <= i / 20.0, as numpy compares), not only to rounding.
int sampledBin(double e) {
  if (!(e <= 5.0)) return 100;
  int i = std::max(1, static_cast<int>(std::ceil(e * 20.0)));
  if (i > 1 && e <= (i - 1) / 20.0) --i;  // e * 20 rounded up past a threshold e is within
  else if (!(e <= i / 20.0)) ++i;         // or down below one it is not
  return i - 1;
}

// WaucMode::kSampled's histograms (`all`: every pixel, `masked`: where the mask is non-zero; either
// may be null), in a pass of their own and out of line, so that the main loop, the default, pays
// nothing for them. An invalid prediction is within no threshold: it adds to no bin. The endpoint
// error as the main loop computes it.
[[gnu::noinline]] void addSampled(uint64_t* all, uint64_t* masked, const float* gt, const float* pred,
                                  const uint8_t* mask, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const float* g = gt + 2 * i;
    const float* p = pred + 2 * i;
    if (!std::isfinite(g[0]) || !std::isfinite(g[1]) || !std::isfinite(p[0]) || !std::isfinite(p[1])) continue;
    const double du = static_cast<double>(p[0]) - g[0], dv = static_cast<double>(p[1]) - g[1];
    const int bin = sampledBin(std::sqrt(du * du + dv * dv));
    if (all != nullptr) ++all[bin];
    if (masked != nullptr && (mask == nullptr || mask[i] != 0)) ++masked[bin];
  }
}

// An accumulator's counters in locals for the pixel loop (the member sums would be reloaded after
// every histogram store). The sums continue from the accumulator's, in pixel order, so that the
// result is the same to the last bit as adding pixel by pixel.
struct Tally {
  uint64_t scored, invalid, outliers;
  double wauc, epe;
  uint64_t* hist;
  void invalidPrediction() { ++scored, ++invalid, ++outliers; }
  void error(double e, double wauc_term, int bin, bool outlier) {
    ++scored;
    epe += e;
    wauc += wauc_term;
    ++hist[bin];
    outliers += outlier;
  }
};

}  // namespace

void FlowErrorAccumulator::add(const float* gt, const float* pred, const uint8_t* mask, size_t n) {
  if (mask == nullptr) accumulate(this, nullptr, gt, pred, nullptr, n);
  else accumulate(nullptr, this, gt, pred, mask, n);
}

void FlowErrorAccumulator::addBoth(FlowErrorAccumulator& all, FlowErrorAccumulator& masked, const float* gt,
                                   const float* pred, const uint8_t* mask, size_t n) {
  accumulate(&all, &masked, gt, pred, mask, n);
}

void FlowErrorAccumulator::accumulate(FlowErrorAccumulator* unmasked, FlowErrorAccumulator* masked, const float* gt,
                                      const float* pred, const uint8_t* mask, size_t n) {
  if (n > 0 && (gt == nullptr || pred == nullptr))
    throw std::invalid_argument("FlowErrorAccumulator::add: null flow image");
  auto tally = [](FlowErrorAccumulator* acc) {
    return acc ? Tally{acc->scored_, acc->invalid_pred_, acc->outliers_, acc->wauc_sum_, acc->epe_sum_, acc->hist_}
               : Tally{};
  };
  Tally a = tally(unmasked), b = tally(masked);
  for (size_t i = 0; i < n; ++i) {
    const float gu = gt[2 * i], gv = gt[2 * i + 1];
    if (!std::isfinite(gu) || !std::isfinite(gv)) continue;
    const bool in_mask = mask == nullptr || mask[i] != 0;
    if (unmasked == nullptr && !in_mask) continue;
    const bool to_a = unmasked != nullptr, to_b = masked != nullptr && in_mask;
    const float pu = pred[2 * i], pv = pred[2 * i + 1];
    if (!std::isfinite(pu) || !std::isfinite(pv)) {
      if (to_a) a.invalidPrediction();
      if (to_b) b.invalidPrediction();
      continue;
    }
    // sqrt of the sum of squares, not hypot (twice this loop's cost): the components are float
    // differences, exact in double, so this is within an ulp or two of hypot; no overflow either.
    const double du = static_cast<double>(pu) - gu, dv = static_cast<double>(pv) - gv;
    const double e = std::sqrt(du * du + dv * dv);
    // Errors >= 5 px are clamped to 5 px: weight 0, the histogram's last bin; no branch.
    const double clamped = std::min(e, kWaucMaxPx);
    const double w = 1.0 - clamped / kWaucMaxPx;
    const int bin = static_cast<int>(clamped * (kHistBins / kWaucMaxPx));
    const bool outlier = isOutlier(e, gu, gv);
    if (to_a) a.error(e, w * w, bin, outlier);
    if (to_b) b.error(e, w * w, bin, outlier);
  }
  auto sampled = [](FlowErrorAccumulator* acc) {
    return acc != nullptr && acc->mode_ == WaucMode::kSampled ? acc->sampled_hist_ : nullptr;
  };
  uint64_t *sampled_a = sampled(unmasked), *sampled_b = sampled(masked);
  if (sampled_a != nullptr || sampled_b != nullptr) addSampled(sampled_a, sampled_b, gt, pred, mask, n);
  auto store = [](const Tally& t, FlowErrorAccumulator* acc) {
    if (acc == nullptr) return;
    acc->scored_ = t.scored, acc->invalid_pred_ = t.invalid, acc->outliers_ = t.outliers;
    acc->wauc_sum_ = t.wauc, acc->epe_sum_ = t.epe;
  };
  store(a, unmasked);
  store(b, masked);
}

void FlowErrorAccumulator::merge(const FlowErrorAccumulator& o) {
  if (o.mode_ != mode_) throw std::invalid_argument("FlowErrorAccumulator::merge: the WAUC modes differ");
  for (int b = 0; b <= kSampledThresholds; ++b) sampled_hist_[b] += o.sampled_hist_[b];
  scored_ += o.scored_;
  invalid_pred_ += o.invalid_pred_;
  outliers_ += o.outliers_;
  wauc_sum_ += o.wauc_sum_;
  epe_sum_ += o.epe_sum_;
  for (int b = 0; b < kHistBins; ++b) hist_[b] += o.hist_[b];
}

double FlowErrorAccumulator::wauc() const {
  if (scored_ == 0) return std::numeric_limits<double>::quiet_NaN();
  if (mode_ == WaucMode::kIntegral) return 100.0 * wauc_sum_ / scored_;
  // A pixel of bin b is within the thresholds b + 1 .. 100, whose weights sum to `tail`.
  double weighted = 0.0, tail = 0.0;
  for (int b = kSampledThresholds - 1; b >= 0; --b) {
    tail += 1.0 - b / 100.0;
    weighted += tail * static_cast<double>(sampled_hist_[b]);
  }
  return 100.0 * weighted / (tail * static_cast<double>(scored_));
}

double FlowErrorAccumulator::averageEndpointError() const {
  const uint64_t n = scored_ - invalid_pred_;
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : epe_sum_ / n;
}

double FlowErrorAccumulator::outlierPercent() const {
  return scored_ == 0 ? std::numeric_limits<double>::quiet_NaN() : 100.0 * outliers_ / scored_;
}

double FlowErrorAccumulator::inlierPercent(double threshold_px) const {
  if (scored_ == 0) return std::numeric_limits<double>::quiet_NaN();
  // Bin b holds errors in [b, b+1) * 0.01 px: errors <= t are the bins below floor(t / 0.01).
  const int bins = std::min(kHistBins, static_cast<int>(std::floor(threshold_px * (kHistBins / kWaucMaxPx))));
  uint64_t count = 0;
  for (int b = 0; b < bins; ++b) count += hist_[b];
  return 100.0 * count / scored_;
}

}  // namespace viper
