// libFuzzer target: two arbitrary image messages, ROS-serialized one after another, through the
// converter's image -> core functions (the one image check, 8-bit, 32SC1, 32FC1 and flow images,
// a flow with its visibility mask): step, size and encoding may disagree, rows may be padded,
// words big-endian. Each must return its problem; none may crash, throw or read outside a message.
// Seeds: images the converter builds (rgb8, mono8, a flow and its mask, 32SC1, 32FC1), and a
// padded big-endian copy.
#include "fuzz_support.h"
#include "message_input.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/image_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  namespace enc = sensor_msgs::image_encodings;
  std_msgs::Header header;
  header.stamp = ros::Time(4, 0);
  viper::FlowField field;
  field.width = 3;
  field.height = 2;
  field.uv = {0.5f, 1, -2, 0, 1e3f, 3, 0, 0, 0.25f, -0.25f, 7, 8};
  field.visible = {255, 0, 255, 255, 0, 0};
  const viper::FlowMessages flow = viper::toFlowMsgs(field, header);
  std::vector<uint8_t> bytes;
  appendMessage(bytes, *flow.flow);
  appendMessage(bytes, *flow.visible);
  writeBytes(dir + "/flow.bin", bytes);

  viper::dataset::Image8 rgb{3, 2, 3, std::vector<uint8_t>(18, 90)};
  const int32_t ids[6] = {0, 1, 2, -1, 70000, 5};
  const float metres[6] = {1.5f, 2, 0, -1, 1e9f, 3};
  bytes.clear();
  appendMessage(bytes, viper::toImageMsg(rgb, header));
  appendMessage(bytes, viper::imageMsg(header, 3, 2, enc::TYPE_32SC1, 4, ids));
  writeBytes(dir + "/rgb_ids.bin", bytes);
  bytes.clear();
  sensor_msgs::Image padded = viper::imageMsg(header, 3, 2, enc::TYPE_32FC1, 4, metres);
  padded.is_bigendian = 1;
  padded.step = 16;
  padded.data.resize(32, 0x3f);
  appendMessage(bytes, padded);
  appendMessage(bytes, viper::toImageMsg(viper::dataset::Image8{3, 2, 1, std::vector<uint8_t>(6, 7)}, header));
  writeBytes(dir + "/padded_mono.bin", bytes);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace enc = sensor_msgs::image_encodings;
  viper::fuzz::MessageInput input(data, size);
  sensor_msgs::Image a, b;
  if (!input.next(a)) return 0;
  input.next(b);
  const size_t pixels = size_t(a.width) * a.height;
  for (const std::string& encoding : {enc::RGB8, enc::MONO8})
    for (auto layout : {viper::ImageLayout::kPacked, viper::ImageLayout::kAnyStep})
      (void)viper::checkImage(a, encoding, b.width, b.height, layout);
  viper::dataset::Image8 image;
  for (const std::string& encoding : {enc::RGB8, enc::MONO8})
    if (viper::imageFromMsg(a, encoding, image).empty() && image.data.size() != pixels * image.channels)
      __builtin_trap();
  std::vector<int32_t> ints;
  if (viper::int32FromMsg(a, ints).empty() && ints.size() != pixels) __builtin_trap();
  std::vector<float> floats;
  if (viper::float32FromMsg(a, floats).empty() && floats.size() != pixels) __builtin_trap();
  viper::dataset::FlowImage flow;
  if (viper::flowFromMsg(a, flow).empty() && flow.uv.size() != 2 * pixels) __builtin_trap();
  viper::FlowField field;
  if (viper::flowFieldFromMsgs(a, b, field).empty() &&
      (field.uv.size() != 2 * pixels || field.visible.size() != pixels))
    __builtin_trap();
  return 0;
}
