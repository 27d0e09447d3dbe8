// Realistic capture frames and file helpers shared by the capture stream tests.
#pragma once

#include "viper/capture/capture_stream.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace viper {
namespace test {

/// A frame like the interceptor writes: a ground plane, a box and a skinned person drawn into a
/// w x h image, with ids, primitives, matrices, textures, one deformed draw and new meshes.
inline CaptureFrame makeFrame(uint64_t number, uint32_t w = 64, uint32_t h = 48) {
  CaptureFrame f;
  f.number = number;
  f.time_s = 12.5 + number / 30.0;
  f.condition = number % 2 ? "rain" : "day";
  f.width = w;
  f.height = h;
  const size_t n = f.pixelCount();
  f.color_rgb.resize(n * 3);
  f.depth_window.resize(n);
  f.draw_ids.resize(n);
  f.primitive_ids.resize(n);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      const size_t p = size_t(y) * w + x;
      uint32_t draw = y < h / 3 ? 0 : (x > w / 2 && y < 2 * h / 3 ? 2 : 1);  // sky, box, ground
      if (x > w / 4 && x < w / 4 + 6 && y > h / 2 && y < h - 4) draw = 3;   // person
      f.draw_ids[p] = draw;
      f.primitive_ids[p] = draw == 0 ? 0 : (x / 4 + y / 4 * 7 + uint32_t(number)) % 97;
      f.depth_window[p] = draw == 0 ? 1.0f : 0.9f + 0.0001f * y + 0.00001f * float(number);
      f.color_rgb[3 * p + 0] = uint8_t(x * 3 + number);
      f.color_rgb[3 * p + 1] = uint8_t(y * 5);
      f.color_rgb[3 * p + 2] = uint8_t(draw * 60);
    }
  }
  for (uint32_t i = 0; i < 3; ++i) {
    DrawRecord d;
    d.index = i;
    d.mesh_key = 0x1000 + i;
    d.vertex_buffer_key = 0x2000 + i;
    d.index_buffer_key = i == 0 ? 0 : 0x3000 + i;
    d.program_key = 0x4000 + (i == 2);
    if (i > 0) d.texture_keys = {0x5000 + i, 0x6000 + i * number};
    d.matrix_flags = kHasWorld | kHasView | kHasProjection;
    d.world(0, 3) = 1.5f * i;
    d.world(1, 3) = -0.25f * float(number);
    d.view(2, 3) = -10.0f;
    d.projection(0, 0) = 1.73f;
    d.projection(3, 2) = -1.0f;
    d.primitive_count = 12 * (i + 1);
    d.visible_pixels = uint32_t(i * 100 + number);
    if (i == 2) {
      d.gaps = number % 2 ? kGapNoMesh | kGapMatrixMissing : kGapNoIds;
      for (int v = 0; v < 8; ++v) d.deformed_clip_xyzw.insert(d.deformed_clip_xyzw.end(),
                                                             {0.1f * v, -0.2f * v + number, 0.5f, 1.0f + v});
    }
    f.draws.push_back(d);
  }
  f.unrecorded_draws = uint32_t(number % 3);
  if (number % 2 == 0) {
    MeshRecord m;
    m.key = 0x1000 + number;
    m.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, float(number)};
    m.indices = {0, 1, 2, 2, 1, 3};
    f.new_meshes.push_back(m);
  }
  return f;
}

inline void expectDrawEq(const DrawRecord& a, const DrawRecord& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.mesh_key, b.mesh_key);
  EXPECT_EQ(a.vertex_buffer_key, b.vertex_buffer_key);
  EXPECT_EQ(a.index_buffer_key, b.index_buffer_key);
  EXPECT_EQ(a.program_key, b.program_key);
  EXPECT_EQ(a.texture_keys, b.texture_keys);
  EXPECT_EQ(a.matrix_flags, b.matrix_flags);
  EXPECT_EQ(a.world, b.world);
  EXPECT_EQ(a.view, b.view);
  EXPECT_EQ(a.projection, b.projection);
  EXPECT_EQ(a.primitive_mode, b.primitive_mode);
  EXPECT_EQ(a.primitive_count, b.primitive_count);
  EXPECT_EQ(a.visible_pixels, b.visible_pixels);
  EXPECT_EQ(a.gaps, b.gaps);
  EXPECT_EQ(a.deformed_clip_xyzw, b.deformed_clip_xyzw);
}

/// Field-by-field equality of two frames (exact: the format is lossless).
inline void expectFrameEq(const CaptureFrame& a, const CaptureFrame& b) {
  EXPECT_EQ(a.number, b.number);
  EXPECT_EQ(a.time_s, b.time_s);
  EXPECT_EQ(a.condition, b.condition);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_TRUE(a.color_rgb == b.color_rgb) << "color_rgb differs, frame " << a.number;
  EXPECT_TRUE(a.depth_window == b.depth_window) << "depth_window differs, frame " << a.number;
  EXPECT_TRUE(a.draw_ids == b.draw_ids) << "draw_ids differs, frame " << a.number;
  EXPECT_TRUE(a.primitive_ids == b.primitive_ids) << "primitive_ids differs, frame " << a.number;
  ASSERT_EQ(a.draws.size(), b.draws.size());
  for (size_t i = 0; i < a.draws.size(); ++i) expectDrawEq(a.draws[i], b.draws[i]);
  EXPECT_EQ(a.unrecorded_draws, b.unrecorded_draws);
  ASSERT_EQ(a.new_meshes.size(), b.new_meshes.size());
  for (size_t i = 0; i < a.new_meshes.size(); ++i) {
    EXPECT_EQ(a.new_meshes[i].key, b.new_meshes[i].key);
    EXPECT_EQ(a.new_meshes[i].positions_xyz, b.new_meshes[i].positions_xyz);
    EXPECT_EQ(a.new_meshes[i].indices, b.new_meshes[i].indices);
  }
}

/// `frame` as CaptureReader::nextWithoutImages returns it: the four images empty.
inline CaptureFrame withoutImages(CaptureFrame frame) {
  frame.color_rgb.clear();
  frame.depth_window.clear();
  frame.draw_ids.clear();
  frame.primitive_ids.clear();
  return frame;
}

/// A fresh path under the temp dir, unique per process and tag; removed by the destructor.
struct TempPath {
  explicit TempPath(const std::string& tag)
      : path((std::getenv("TMPDIR") ? std::string(std::getenv("TMPDIR")) : std::string("/tmp")) +
             "/viper_test_" + tag + "_" + std::to_string(::getpid()) + ".vcap") {}
  ~TempPath() { std::remove(path.c_str()); }
  std::string path;
};

inline std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::string& path, const std::string& bytes, bool append = false) {
  std::ofstream out(path, std::ios::binary | (append ? std::ios::app : std::ios::trunc));
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// Writes `count` frames made by makeFrame, compressed by `codec`, and returns the offset of every
/// chunk (the last one is the end marker's) as the writer's byte count before each write.
inline std::vector<uint64_t> writeStream(const std::string& path, int count, uint32_t w = 64, uint32_t h = 48,
                                         CaptureCodec codec = CaptureCodec::kZstd) {
  CaptureHeader header;
  header.program = "town";
  header.profile = "town_profile.yaml";
  header.codec = codec;
  CaptureWriter writer(path, header, 3);
  std::vector<uint64_t> offsets;
  for (int i = 0; i < count; ++i) {
    offsets.push_back(writer.bytesWritten());
    writer.write(makeFrame(uint64_t(i), w, h));
  }
  offsets.push_back(writer.bytesWritten());
  writer.close();
  return offsets;
}

/// A version 5 payload (encodeFramePayload's) laid out as versions 2 to 4 lay it out: each image's
/// element count right before its elements instead of all four counts in the head.
inline std::string toVersion4Payload(const std::string& v5) {
  uint32_t condition;
  std::memcpy(&condition, v5.data() + 16, 4);
  const size_t fields = 8 + 8 + 4 + condition + 4 + 4;  // number to height
  std::string v4 = v5.substr(0, fields);
  size_t at = fields + 4 * 8;
  const size_t element_bytes[4] = {1, 4, 4, 4};
  for (int k = 0; k < 4; ++k) {
    uint64_t count;
    std::memcpy(&count, v5.data() + fields + 8 * k, 8);
    v4.append(v5, fields + 8 * k, 8);
    v4.append(v5, at, count * element_bytes[k]);
    at += count * element_bytes[k];
  }
  v4.append(v5, at, std::string::npos);
  return v4;
}

}  // namespace test
}  // namespace viper
