// Writes a seed corpus for capture_reader_fuzzer: a valid two-frame stream and a bare payload.
#include "viper/capture/capture_stream.h"

#include <cstdio>
#include <fstream>
#include <string>

namespace {

viper::CaptureFrame smallFrame(uint64_t number) {
  viper::CaptureFrame f;
  f.number = number;
  f.time_s = 0.5 * number;
  f.condition = "day";
  f.width = 4;
  f.height = 3;
  f.color_rgb.assign(36, uint8_t(40 + number));
  f.depth_window.assign(12, 0.5f);
  f.draw_ids = {0, 1, 1, 2, 0, 1, 2, 2, 0, 0, 1, 2};
  f.primitive_ids = {0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 1, 1};
  for (uint32_t i = 0; i < 2; ++i) {
    viper::DrawRecord d;
    d.index = i;
    d.mesh_key = 10 + i;
    d.texture_keys = {77};
    d.matrix_flags = viper::kHasWorld;
    d.primitive_count = 2;
    if (i == 1) d.deformed_clip_xyzw = {0, 0, 0.5f, 1, 1, 0, 0.5f, 1, 0, 1, 0.5f, 1};
    f.draws.push_back(d);
  }
  viper::MeshRecord m;
  m.key = 10;
  m.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  f.new_meshes.push_back(m);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  viper::CaptureHeader header;
  header.program = "seed";
  {
    viper::CaptureWriter writer(dir + "/stream.vcap", header, 1);
    writer.write(smallFrame(0));
    writer.write(smallFrame(1));
  }
  std::ofstream(dir + "/payload.bin", std::ios::binary) << viper::encodeFramePayload(smallFrame(2));
  return 0;
}
