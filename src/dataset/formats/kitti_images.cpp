#include "viper/dataset/kitti_images.h"

#include "deflate_writers.h"

#include <cmath>
#include <stdexcept>

namespace viper::dataset {
namespace {

// round(x * scale) + offset if it is finite and lands in 0..65535 (and at least `min`), else 0.
uint16_t encode(float x, double scale, double offset, double min, KittiEncodeStats& stats) {
  if (!std::isfinite(x)) {
    ++stats.not_finite;
    return 0;
  }
  const double value = std::nearbyint(static_cast<double>(x) * scale) + offset;
  if (value < min || value > 65535.0) {
    ++stats.out_of_range;
    return 0;
  }
  return static_cast<uint16_t>(value);
}

}  // namespace

std::vector<uint16_t> kittiFlowValues(const FlowImage& flow, KittiEncodeStats* stats) {
  if (flow.uv.size() != 2 * flow.pixels())
    throw std::invalid_argument("KITTI flow: " + std::to_string(flow.uv.size()) + " values for " +
                                std::to_string(flow.width) + "x" + std::to_string(flow.height) + " px");
  KittiEncodeStats counted;
  std::vector<uint16_t> out(3 * flow.pixels(), 0);
  for (size_t i = 0; i < flow.pixels(); ++i) {
    KittiEncodeStats pixel;
    const uint16_t u = encode(flow.uv[2 * i], 64.0, 32768.0, 0.0, pixel);
    const uint16_t v = encode(flow.uv[2 * i + 1], 64.0, 32768.0, 0.0, pixel);
    if (pixel.not_finite > 0) {
      ++counted.not_finite;
    } else if (pixel.out_of_range > 0) {
      ++counted.out_of_range;
    } else {
      out[3 * i] = u;
      out[3 * i + 1] = v;
      out[3 * i + 2] = 1;
      ++counted.valid;
    }
  }
  if (stats != nullptr) *stats = counted;
  return out;
}

std::vector<uint16_t> kittiDepthValues(const float* depth_m, uint32_t width, uint32_t height,
                                       KittiEncodeStats* stats) {
  const size_t n = static_cast<size_t>(width) * height;
  if (n > 0 && depth_m == nullptr) throw std::invalid_argument("KITTI depth: no values for a non-empty image");
  KittiEncodeStats counted;
  std::vector<uint16_t> out(n);
  for (size_t i = 0; i < n; ++i) {
    const float d = depth_m[i];
    if (std::isfinite(d) && d > 0.0f && std::nearbyint(static_cast<double>(d) * 256.0) < 1.0) {
      out[i] = 1;  // a positive depth under 1/512 m stays valid (the devkit writes max(depth * 256, 1))
      ++counted.valid;
      continue;
    }
    if (std::isfinite(d) && d <= 0.0f) {
      ++counted.out_of_range;
      continue;
    }
    out[i] = encode(d, 256.0, 0.0, 1.0, counted);
    if (out[i] != 0) ++counted.valid;
  }
  if (stats != nullptr) *stats = counted;
  return out;
}

KittiEncodeStats writeKittiFlow(const std::string& path, const FlowImage& flow, const ImageWriteOptions& options) {
  KittiEncodeStats stats;
  const std::vector<uint16_t> values = kittiFlowValues(flow, &stats);
  detail::writeFileAtomically(path,
                              detail::pngBytes16(values.data(), flow.width, flow.height, detail::PngColor::kRgb,
                                                 options.png_compression_level),
                              "KITTI flow PNG", options.digests);
  return stats;
}

KittiEncodeStats writeKittiDepth(const std::string& path, const float* depth_m, uint32_t width, uint32_t height,
                                 const ImageWriteOptions& options) {
  KittiEncodeStats stats;
  const std::vector<uint16_t> values = kittiDepthValues(depth_m, width, height, &stats);
  detail::writeFileAtomically(path,
                              detail::pngBytes16(values.data(), width, height, detail::PngColor::kGray,
                                                 options.png_compression_level),
                              "KITTI depth PNG", options.digests);
  return stats;
}

}  // namespace viper::dataset
