#include "viper/ros/conversions/amodal_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>

namespace viper {

AmodalInstanceArray toAmodalInstanceArrayMsg(const FrameAmodal& amodal, const std_msgs::Header& header) {
  AmodalInstanceArray msg;
  msg.header = header;
  msg.objects.resize(amodal.objects.size());
  for (size_t i = 0; i < amodal.objects.size(); ++i) {
    const AmodalObject& a = amodal.objects[i];
    AmodalInstance& m = msg.objects[i];
    m.track_id = a.track_id;
    m.class_id = a.class_id;
    if (!a.box.empty()) {
      m.box.x_offset = static_cast<uint32_t>(a.box.x_min);
      m.box.y_offset = static_cast<uint32_t>(a.box.y_min);
      m.box.width = static_cast<uint32_t>(a.box.width());
      m.box.height = static_cast<uint32_t>(a.box.height());
    }
    m.amodal_pixels = a.amodal_pixels;
    m.visible_pixels = a.visible_pixels;
    m.visible_fraction = static_cast<float>(a.visible_fraction);
    m.truncation = static_cast<float>(a.truncation);
    m.occlusion = static_cast<uint8_t>(a.occlusion);
    m.difficulty = static_cast<uint8_t>(a.difficulty);
    m.mask.header = header;
    m.mask.width = m.box.width;
    m.mask.height = m.box.height;
    m.mask.encoding = sensor_msgs::image_encodings::MONO8;
    m.mask.is_bigendian = false;
    m.mask.step = m.box.width;
    m.mask.data.resize(a.mask.size());
    for (size_t p = 0; p < a.mask.size(); ++p) m.mask.data[p] = a.mask[p] ? 255 : 0;
  }
  return msg;
}

void amodalColor(int32_t track_id, uint8_t rgb[3]) {
  const double hue = std::fmod(0.618033988749895 * track_id, 1.0) * 6.0;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const uint8_t up = static_cast<uint8_t>(std::lround(255 * f)), down = static_cast<uint8_t>(255 - up);
  const uint8_t table[6][3] = {{255, up, 0},   {down, 255, 0}, {0, 255, up},
                               {0, down, 255}, {up, 0, 255},   {255, 0, down}};
  for (int c = 0; c < 3; ++c) rgb[c] = table[sector][c];
}

void renderAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, const std_msgs::Header& header,
                         sensor_msgs::Image& out) {
  out.header = header;
  out.width = amodal.width, out.height = amodal.height;
  out.encoding = sensor_msgs::image_encodings::RGB8;
  out.is_bigendian = false;
  out.step = 3 * out.width;
  out.data.assign(static_cast<size_t>(out.step) * out.height, 0);
  // Visible parts filled first, occluded parts hatched after, over whatever hides them (another
  // object's fill between the stripes shows what is in front).
  for (const bool visible_pass : {true, false})
    for (const AmodalObject& a : amodal.objects) {
      uint8_t rgb[3];
      amodalColor(a.track_id, rgb);
      for (int y = a.box.y_min; y <= a.box.y_max; ++y)
        for (int x = a.box.x_min; x <= a.box.x_max; ++x) {
          if (!a.mask[static_cast<size_t>(y - a.box.y_min) * a.box.width() + (x - a.box.x_min)]) continue;
          const size_t p = static_cast<size_t>(y) * out.width + x;
          const bool visible = instance_ids[p] == a.track_id;
          if (visible_pass ? visible : (!visible && (x + y) % 6 < 2)) std::copy_n(rgb, 3, out.data.data() + 3 * p);
        }
    }
}

}  // namespace viper
