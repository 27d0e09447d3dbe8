// libFuzzer target: arbitrary raw messages of one frame (a draw list, the draw id, color, depth and
// primitive id images, a mesh store), ROS-serialized one after another, through the converter's
// message -> core functions: draw lists whose indices point nowhere, images whose step, size or
// encoding disagree with the frame. Each must return its problem (or leave the mesh out); none may
// crash, throw or read outside a message.
// Seeds: the messages frameMessages builds for a captured frame, whole and without the mesh store.
#include "fuzz_support.h"
#include "message_input.h"
#include "seed_frame.h"
#include "viper/ros/conversions/frame_conversions.h"

#include <boost/make_shared.hpp>

#include <string>

namespace {

std::vector<uint8_t> serializedFrame(const viper::FrameMessages& m, bool with_meshes) {
  std::vector<uint8_t> out;
  viper::fuzz::appendMessage(out, *m.draws);
  for (const auto& image : {m.draw_ids, m.color, m.depth, m.primitive_ids}) viper::fuzz::appendMessage(out, *image);
  if (with_meshes) viper::fuzz::appendMessage(out, *m.mesh_store);
  return out;
}

}  // namespace

void viper::fuzz::writeSeeds(const std::string& dir) {
  std_msgs::Header header;
  header.stamp = ros::Time(12, 500);
  header.frame_id = "camera_optical";
  viper::MeshStoreAccumulator meshes;
  const viper::FrameMessages m = viper::frameMessages(seedFrame(3), header, meshes);
  writeBytes(dir + "/frame.bin", serializedFrame(m, true));
  writeBytes(dir + "/frame_no_meshes.bin", serializedFrame(m, false));
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  viper::fuzz::MessageInput input(data, size);
  viper::FrameMessages m;
  m.draws = boost::make_shared<viper::DrawList>();
  m.draw_ids = boost::make_shared<sensor_msgs::Image>();
  m.color = boost::make_shared<sensor_msgs::Image>();
  m.depth = boost::make_shared<sensor_msgs::Image>();
  m.primitive_ids = boost::make_shared<sensor_msgs::Image>();
  if (!input.next(*m.draws) || !input.next(*m.draw_ids) || !input.next(*m.color) || !input.next(*m.depth) ||
      !input.next(*m.primitive_ids))
    return 0;
  auto store = boost::make_shared<viper::MeshStore>();
  if (input.next(*store)) {
    std::vector<std::string> problems;
    for (const viper::MeshRecord& mesh : viper::fromMeshStoreMsg(*store, problems))
      if (mesh.positions_xyz.size() % 3 != 0 || mesh.indices.size() % 3 != 0) __builtin_trap();
    m.mesh_store = store;
  }

  viper::CaptureFrame frame;
  std::vector<float> depth_m;
  if (viper::frameFromMessages(m, frame, &depth_m).empty()) {
    if (frame.draw_ids.size() != frame.pixelCount() || frame.color_rgb.size() != 3 * frame.pixelCount() ||
        frame.depth_window.size() != frame.pixelCount() || depth_m.size() != frame.pixelCount())
      __builtin_trap();
    (void)viper::validateFrame(frame);
  }
  return 0;
}
