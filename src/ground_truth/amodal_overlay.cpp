#include "viper/ground_truth/amodal_overlay.h"

#include <algorithm>
#include <cmath>

namespace viper {

void amodalColor(int32_t track_id, uint8_t rgb[3]) {
  const double hue = std::fmod(0.618033988749895 * track_id, 1.0) * 6.0;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const uint8_t up = static_cast<uint8_t>(std::lround(255 * f)), down = static_cast<uint8_t>(255 - up);
  const uint8_t table[6][3] = {{255, up, 0},   {down, 255, 0}, {0, 255, up},
                               {0, down, 255}, {up, 0, 255},   {255, 0, down}};
  for (int c = 0; c < 3; ++c) rgb[c] = table[sector][c];
}

void paintAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, uint8_t* rgb) {
  // Visible parts filled first, occluded parts hatched after, over whatever hides them (another
  // object's fill between the stripes shows what is in front).
  for (const bool visible_pass : {true, false})
    for (const AmodalObject& a : amodal.objects) {
      uint8_t color[3];
      amodalColor(a.track_id, color);
      for (int y = a.box.y_min; y <= a.box.y_max; ++y)
        for (int x = a.box.x_min; x <= a.box.x_max; ++x) {
          if (!a.mask[static_cast<size_t>(y - a.box.y_min) * a.box.width() + (x - a.box.x_min)]) continue;
          const size_t p = static_cast<size_t>(y) * amodal.width + x;
          const bool visible = instance_ids[p] == a.track_id;
          if (visible_pass ? visible : (!visible && (x + y) % 6 < 2)) std::copy_n(color, 3, rgb + 3 * p);
        }
    }
}

}  // namespace viper
