// KITTI's 16-bit PNG encodings of optical flow (KITTI flow 2012/2015 devkit: flow_read.m /
// flow_write.m, io_flow.h) and depth (KITTI depth completion devkit: io_depth.h, readme.txt), as
// the benchmarks' readers decode them. docs/training_formats.md. ROS-free.
#pragma once

#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_images.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// Pixels written as invalid because their value cannot be encoded.
struct KittiEncodeStats {
  size_t valid = 0;         ///< pixels written valid
  size_t not_finite = 0;    ///< no value (NaN, +-inf): invalid, as they are in the input
  size_t out_of_range = 0;  ///< a value beyond the encoding's range, written invalid (not clamped)
};

/// KITTI flow of `flow`: 3 uint16 a pixel, red = round(u * 64) + 2^15, green = round(v * 64) + 2^15,
/// blue = 1 where valid; all 0 where either component is not finite or out of range (encoded
/// outside 0..65535: |flow| beyond about 512 px). Readers decode (value - 2^15) / 64: within
/// 1/128 px of the input.
std::vector<uint16_t> kittiFlowValues(const FlowImage& flow, KittiEncodeStats* stats = nullptr);

/// KITTI depth of `depth_m` (width * height metres, row-major): uint16 round(depth * 256), at least 1
/// for a positive depth; 0 (invalid) where the depth is not finite, not positive, or beyond
/// 65535 / 256 = 255.996 m. Readers decode value / 256: within 1/512 m.
std::vector<uint16_t> kittiDepthValues(const float* depth_m, uint32_t width, uint32_t height,
                                       KittiEncodeStats* stats = nullptr);

/// Writes kittiFlowValues as a 16-bit RGB PNG (written under a temporary name and renamed). Throws
/// std::invalid_argument for a flow whose sizes do not match its values, std::runtime_error naming
/// `path` if it cannot be written. Returns what was encoded.
KittiEncodeStats writeKittiFlow(const std::string& path, const FlowImage& flow,
                                const ImageWriteOptions& options = ImageWriteOptions());

/// Writes kittiDepthValues as a 16-bit gray PNG; otherwise as writeKittiFlow.
KittiEncodeStats writeKittiDepth(const std::string& path, const float* depth_m, uint32_t width, uint32_t height,
                                 const ImageWriteOptions& options = ImageWriteOptions());

}  // namespace viper::dataset
