#include "viper/core/flow_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {

void FlowErrorAccumulator::add(const float* gt, const float* pred, const uint8_t* mask, size_t n) {
  if (n > 0 && (gt == nullptr || pred == nullptr))
    throw std::invalid_argument("FlowErrorAccumulator::add: null flow image");
  for (size_t i = 0; i < n; ++i) {
    const float gu = gt[2 * i], gv = gt[2 * i + 1];
    if (!std::isfinite(gu) || !std::isfinite(gv) || (mask != nullptr && mask[i] == 0)) continue;
    ++scored_;
    const float pu = pred[2 * i], pv = pred[2 * i + 1];
    if (!std::isfinite(pu) || !std::isfinite(pv)) {
      ++invalid_pred_;
      ++outliers_;
      continue;
    }
    const double e = std::hypot(static_cast<double>(pu) - gu, static_cast<double>(pv) - gv);
    epe_sum_ += e;
    if (e < kWaucMaxPx) {
      const double w = 1.0 - e / kWaucMaxPx;
      wauc_sum_ += w * w;
      ++hist_[static_cast<int>(e * (kHistBins / kWaucMaxPx))];
    }
    if (e > 3.0 && e > 0.05 * std::hypot(static_cast<double>(gu), static_cast<double>(gv))) ++outliers_;
  }
}

void FlowErrorAccumulator::merge(const FlowErrorAccumulator& o) {
  scored_ += o.scored_;
  invalid_pred_ += o.invalid_pred_;
  outliers_ += o.outliers_;
  wauc_sum_ += o.wauc_sum_;
  epe_sum_ += o.epe_sum_;
  for (int b = 0; b < kHistBins; ++b) hist_[b] += o.hist_[b];
}

double FlowErrorAccumulator::wauc() const {
  return scored_ == 0 ? std::numeric_limits<double>::quiet_NaN() : 100.0 * wauc_sum_ / scored_;
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
