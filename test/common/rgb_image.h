// Test images drawn from a formula: what the dataset tests and the player tests' layout
// (test/ros/viper_test_layout.h) write and compare.
#pragma once

#include "viper/dataset/viper_images.h"

#include <array>
#include <cstdint>

namespace viper {
namespace test {

/// A width x height RGB image whose pixel (x, y) is `rgb(x, y)` (any callable returning
/// std::array<uint8_t, 3>), rows top first.
template <typename Rgb>
dataset::Image8 rgbImage(uint32_t width, uint32_t height, Rgb rgb) {
  dataset::Image8 im;
  im.width = width, im.height = height, im.channels = 3;
  im.data.resize(im.pixels() * 3);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const std::array<uint8_t, 3> p = rgb(x, y);
      uint8_t* out = &im.data[3 * (static_cast<size_t>(y) * width + x)];
      out[0] = p[0], out[1] = p[1], out[2] = p[2];
    }
  return im;
}

}  // namespace test
}  // namespace viper
