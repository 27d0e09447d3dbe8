#include "viper/ground_truth/semantic_overlay.h"

#include "pixel_kernels.h"

#include <algorithm>
#include <array>

namespace viper {
namespace {

using Palette = std::array<std::array<uint8_t, 3>, 256>;

Palette palette(const ClassTable& classes) {
  Palette p{};
  for (size_t c = 0; c < classes.size() && c < 256; ++c) p[c] = classes.at(static_cast<int>(c)).rgb;
  return p;
}

// The reference: one pixel at a time (and the pixels after the vector kernels' blocks).
void colorizeScalar(const uint8_t* ids, size_t n, const Palette& p, uint8_t* rgb) {
  for (size_t i = 0; i < n; ++i) {
    const auto& c = p[ids[i]];
    rgb[3 * i] = c[0], rgb[3 * i + 1] = c[1], rgb[3 * i + 2] = c[2];
  }
}

void overlayScalar(const uint8_t* color, const uint8_t* ids, size_t n, const Palette& p, int a, uint8_t* rgb) {
  for (size_t i = 0; i < n; ++i) {
    const int k = ids[i] == 0 ? 0 : a;
    for (int ch = 0; ch < 3; ++ch)
      rgb[3 * i + ch] = static_cast<uint8_t>((color[3 * i + ch] * (256 - k) + p[ids[i]][ch] * k + 128) >> 8);
  }
}

// The palette as the vector kernels take it: r | g << 8 | b << 16.
std::array<uint32_t, 256> packed(const Palette& p) {
  std::array<uint32_t, 256> out;
  for (size_t c = 0; c < 256; ++c) out[c] = p[c][0] | uint32_t{p[c][1]} << 8 | uint32_t{p[c][2]} << 16;
  return out;
}

}  // namespace

void colorizeClasses(const uint8_t* ids, size_t n, const ClassTable& classes, uint8_t* rgb, Instructions instructions) {
  const Palette p = palette(classes);
  size_t done = 0;
  const Instructions path = pixel_kernels::kernelPath(instructions);
  if (path != Instructions::kScalar) done = pixel_kernels::colorize(path, ids, n, packed(p).data(), rgb);
  colorizeScalar(ids + done, n - done, p, rgb + 3 * done);
}

void overlayClasses(const uint8_t* color, const uint8_t* ids, size_t n, const ClassTable& classes, float alpha,
                    uint8_t* rgb, Instructions instructions) {
  const Palette p = palette(classes);
  const int a = static_cast<int>(std::clamp(alpha, 0.0f, 1.0f) * 256.0f + 0.5f);  // 8.8 fixed point
  size_t done = 0;
  const Instructions path = pixel_kernels::kernelPath(instructions);
  if (path != Instructions::kScalar && a >= 0 && a <= 256)  // not for a NaN alpha
    done = pixel_kernels::overlay(path, color, ids, n, packed(p).data(), a, rgb);
  overlayScalar(color + 3 * done, ids + done, n - done, p, a, rgb + 3 * done);
}

}  // namespace viper
