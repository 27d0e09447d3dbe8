// Optical flow scores as VIPER and KITTI report them: WAUC, average endpoint error, outlier rate.
#pragma once

#include <cstddef>
#include <cstdint>

namespace viper {

/// How FlowErrorAccumulator::wauc() weighs the inlier curve (docs/evaluate.md, "Flow").
enum class WaucMode {
  kIntegral,  ///< the curve integrated over [0, 5] px with weight 1 - x/5, in closed form (default)
  kSampled,   ///< the curve at 100 thresholds i/20 px with weights 1 - (i-1)/100 (Spring's getWAUC)
};

/// Accumulates flow errors over frames. Flows are interleaved (u, v) floats in pixels; a pixel is
/// scored where both ground-truth components are finite and, if a mask is given, the mask is
/// non-zero. A non-finite prediction on a scored pixel counts as an infinite error (it is never
/// within any threshold and is an outlier); it is left out of the average endpoint error and
/// counted in invalidPredictions().
class FlowErrorAccumulator {
 public:
  /// Largest threshold of the WAUC curve, in pixels (VIPER: 5 px).
  static constexpr double kWaucMaxPx = 5.0;

  explicit FlowErrorAccumulator(WaucMode mode = WaucMode::kIntegral) : mode_(mode) {}

  /// Adds `n` pixels. `mask` may be null (score every pixel with valid ground truth).
  void add(const float* gt_uv, const float* pred_uv, const uint8_t* mask, size_t n);
  /// Adds `n` pixels to `all` (mask ignored) and to `masked` (where `mask` is non-zero; every
  /// pixel if it is null) in one pass, each endpoint error computed once: the same as
  /// all.add(gt_uv, pred_uv, nullptr, n) followed by masked.add(gt_uv, pred_uv, mask, n).
  static void addBoth(FlowErrorAccumulator& all, FlowErrorAccumulator& masked, const float* gt_uv,
                      const float* pred_uv, const uint8_t* mask, size_t n);
  /// Adds another accumulator's pixels. Throws std::invalid_argument if its WaucMode differs.
  void merge(const FlowErrorAccumulator& other);

  /// Weighted area under the curve, 0..100. kIntegral: the fraction of pixels with endpoint error
  /// <= x, integrated over x in [0, 5] px with weight 1 - x/5, normalised by the weights' integral,
  /// computed exactly: a pixel with error e contributes (1 - e/5)^2 if e < 5, else 0. kSampled:
  /// sum_i w_i p(i/20) / sum_i w_i over i = 1..100, w_i = 1 - (i-1)/100, p(x) the fraction of
  /// pixels with error <= x. NaN if no pixel was scored.
  double wauc() const;
  /// Mean endpoint error (px) over scored pixels with a finite prediction; NaN if none.
  double averageEndpointError() const;
  /// KITTI outlier rate in percent: error > 3 px and > 5% of the ground-truth flow magnitude.
  double outlierPercent() const;
  /// Percentage of scored pixels with endpoint error below threshold_px, resolved to 0.01 px
  /// (for curves); threshold_px in [0, 5] (larger thresholds count errors below 5 px).
  double inlierPercent(double threshold_px) const;

  WaucMode waucMode() const { return mode_; }
  uint64_t scoredPixels() const { return scored_; }
  uint64_t invalidPredictions() const { return invalid_pred_; }

 private:
  static constexpr int kHistBins = 500;  // 0.01 px bins over [0, 5) for inlierPercent()
  static constexpr int kSampledThresholds = 100;  // WaucMode::kSampled: i/20 px, i = 1..100
  /// Adds pixels to `unmasked` and/or `masked` (either may be null).
  static void accumulate(FlowErrorAccumulator* unmasked, FlowErrorAccumulator* masked, const float* gt_uv,
                         const float* pred_uv, const uint8_t* mask, size_t n);
  uint64_t scored_ = 0, invalid_pred_ = 0, outliers_ = 0;
  double wauc_sum_ = 0.0, epe_sum_ = 0.0;
  uint64_t hist_[kHistBins + 1] = {};  // the last bin takes errors >= 5 px, so that adding needs no branch
  WaucMode mode_;
  // kSampled: pixels by the first threshold i/20 px their error is within (bin i - 1); the last: none
  uint64_t sampled_hist_[kSampledThresholds + 1] = {};
};

/// Fills the missing vectors (a non-finite u or v) of a width x height flow image in place, as the
/// KITTI devkit does before it scores an estimate (io_flow.h, FlowImage::interpolateBackground):
/// in each row, a gap between two vectors takes their per-component minimum and the row's ends
/// copy its first and last vector; then in each column the ends copy its first and last vector. A
/// frame without any vector stays missing. Throws std::invalid_argument on a null image.
void fillMissingFlow(float* uv, uint32_t width, uint32_t height);

}  // namespace viper
