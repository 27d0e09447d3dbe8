// The in-memory flow field that the dataset readers return and the writers take.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper::dataset {

/// Dense optical flow, as on the package's flow topics (32FC2): `uv` holds width*height pairs
/// (u, v) in pixels, interleaved, row-major from the top-left pixel; u points right, v down.
/// A non-finite component (NaN, +-inf) means "no valid flow" there.
struct FlowImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<float> uv;  ///< 2 * width * height values

  size_t pixels() const { return static_cast<size_t>(width) * height; }
};

}  // namespace viper::dataset
