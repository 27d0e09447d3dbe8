#include "textures.h"

#include "classes.h"

#include <algorithm>
#include <random>

namespace viper {
namespace world {

float textureMetres(uint8_t class_id) {
  switch (class_id) {
    case kBuilding: return 12.0f;
    case kRoad: return 6.0f;
    case kSidewalk: return 4.0f;
    case kTerrain: return 5.0f;
    default: return 2.0f;
  }
}

std::vector<uint8_t> classTexture(uint8_t class_id) {
  const int n = kTextureSize;
  std::vector<uint8_t> px(n * n * 4);
  std::mt19937 rng(1000u + class_id);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      float noise = float(rng() % 1000u) / 1000.0f;
      float v = 0.92f + 0.08f * noise, a = 0.0f;
      float r = v, g = v, b = v;
      if (class_id == kBuilding) {
        // 4x4 windows per repeat: dark glass with a frame, lit at night via alpha.
        int cx = x % 16, cy = y % 16;
        bool window = cx >= 4 && cx < 13 && cy >= 3 && cy < 12;
        if (window) {
          r = 0.35f + 0.05f * noise, g = 0.4f + 0.05f * noise, b = 0.48f + 0.05f * noise;
          // Lit windows at night: alpha 1 for about half of the windows, 0.5 for the others.
          a = ((x / 16) * 7 + (y / 16) * 3 + (x / 16) * (y / 16)) % 5 < 2 ? 1.0f : 0.5f;
        }
      } else if (class_id == kRoad) {
        v = 0.8f + 0.2f * noise * noise;
        r = g = b = v;
      } else if (class_id == kSidewalk) {
        bool joint = x % 16 == 0 || y % 16 == 0;
        r = g = b = joint ? 0.7f : 0.9f + 0.1f * noise;
      } else if (class_id == kTerrain || class_id == kVegetation || class_id == kTree) {
        v = 0.75f + 0.25f * noise;
        r = v * 0.95f, g = v, b = v * 0.9f;
      }
      uint8_t* p = &px[4 * (y * n + x)];
      p[0] = uint8_t(std::clamp(r, 0.0f, 1.0f) * 255.0f + 0.5f);
      p[1] = uint8_t(std::clamp(g, 0.0f, 1.0f) * 255.0f + 0.5f);
      p[2] = uint8_t(std::clamp(b, 0.0f, 1.0f) * 255.0f + 0.5f);
      p[3] = uint8_t(a * 255.0f);
    }
  return px;
}

}  // namespace world
}  // namespace viper
