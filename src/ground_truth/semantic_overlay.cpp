#include "viper/ground_truth/semantic_overlay.h"

#include <algorithm>
#include <array>

namespace viper {
namespace {

std::array<std::array<uint8_t, 3>, 256> palette(const ClassTable& classes) {
  std::array<std::array<uint8_t, 3>, 256> p{};
  for (size_t c = 0; c < classes.size() && c < 256; ++c) p[c] = classes.at(static_cast<int>(c)).rgb;
  return p;
}

}  // namespace

void colorizeClasses(const uint8_t* ids, size_t n, const ClassTable& classes, uint8_t* rgb) {
  const auto p = palette(classes);
  for (size_t i = 0; i < n; ++i) {
    const auto& c = p[ids[i]];
    rgb[3 * i] = c[0], rgb[3 * i + 1] = c[1], rgb[3 * i + 2] = c[2];
  }
}

void overlayClasses(const uint8_t* color, const uint8_t* ids, size_t n, const ClassTable& classes, float alpha,
                    uint8_t* rgb) {
  const auto p = palette(classes);
  const int a = static_cast<int>(std::clamp(alpha, 0.0f, 1.0f) * 256.0f + 0.5f);  // 8.8 fixed point
  for (size_t i = 0; i < n; ++i) {
    const int k = ids[i] == 0 ? 0 : a;
    for (int ch = 0; ch < 3; ++ch)
      rgb[3 * i + ch] = static_cast<uint8_t>((color[3 * i + ch] * (256 - k) + p[ids[i]][ch] * k + 128) >> 8);
  }
}

}  // namespace viper
