#include "viper/ros/conversions/amodal_conversions.h"

#include <sensor_msgs/image_encodings.h>

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

void renderAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, const std_msgs::Header& header,
                         sensor_msgs::Image& out) {
  out.header = header;
  out.width = amodal.width, out.height = amodal.height;
  out.encoding = sensor_msgs::image_encodings::RGB8;
  out.is_bigendian = false;
  out.step = 3 * out.width;
  out.data.assign(static_cast<size_t>(out.step) * out.height, 0);
  paintAmodalOverlay(amodal, instance_ids, out.data.data());
}

}  // namespace viper
