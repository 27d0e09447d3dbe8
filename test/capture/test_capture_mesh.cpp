// Mesh extraction from shadow buffers and frame finishing (row flip, id decoding, visible pixels).
#include "frame_sink.h"
#include "mesh_extract.h"
#include "viper/core/content_key.h"

#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <cstring>

using namespace viper;
using namespace viper::capture;

namespace {

std::vector<uint8_t> bytesOf(const std::vector<float>& v) {
  std::vector<uint8_t> b(v.size() * sizeof(float));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

}  // namespace

TEST(MeshExtract, IndexedWithStrideAndBaseVertexKeepsTheUsedRange) {
  // Interleaved x, y, z, w(eight); vertices 0-1 unused, draw uses 2..5 via base vertex 2.
  std::vector<float> v;
  for (int i = 0; i < 6; ++i) v.insert(v.end(), {float(i), float(10 * i), float(100 * i), -1.0f});
  const std::vector<uint8_t> vb = bytesOf(v);
  const std::vector<uint16_t> idx = {9, 9, 0, 1, 2, 0, 2, 3};  // first 2 indices skipped by the offset
  DrawRange r;
  r.mode = GL_TRIANGLES;
  r.index_data = reinterpret_cast<const uint8_t*>(idx.data());
  r.index_bytes = idx.size() * 2;
  r.index_type = GL_UNSIGNED_SHORT;
  r.index_offset = 4;
  r.count = 6;
  r.base_vertex = 2;
  PositionLayout layout{3, GL_FLOAT, 16, 0};
  ExtractedMesh m;
  ASSERT_TRUE(extractMesh(vb, layout, r, m));
  EXPECT_EQ(m.first_vertex, 2u);
  EXPECT_EQ(m.vertex_count, 4u);
  const std::vector<float> expected = {2, 20, 200, 3, 30, 300, 4, 40, 400, 5, 50, 500};
  EXPECT_EQ(m.mesh.positions_xyz, expected);
  EXPECT_EQ(m.mesh.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  std::string bytes(reinterpret_cast<const char*>(expected.data()), expected.size() * 4);
  const std::vector<uint32_t> ind = {0, 1, 2, 0, 2, 3};
  bytes.append(reinterpret_cast<const char*>(ind.data()), ind.size() * 4);
  EXPECT_EQ(m.mesh.key, contentKey(bytes));
}

TEST(MeshExtract, SameShapeElsewhereInTheBufferHasTheSameKey) {
  const std::vector<float> a = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<float> b = {5, 5, 5};
  b.insert(b.end(), a.begin(), a.end());
  DrawRange r;
  r.count = 3;
  ExtractedMesh ma, mb;
  ASSERT_TRUE(extractMesh(bytesOf(a), PositionLayout{3, GL_FLOAT, 0, 0}, r, ma));
  r.first = 1;
  ASSERT_TRUE(extractMesh(bytesOf(b), PositionLayout{3, GL_FLOAT, 0, 0}, r, mb));
  EXPECT_EQ(ma.mesh.key, mb.mesh.key);
  EXPECT_EQ(mb.first_vertex, 1u);
}

TEST(MeshExtract, RefusesWhatItCannotExtract) {
  const std::vector<uint8_t> vb = bytesOf({0, 0, 0, 1, 0, 0, 0, 1, 0});
  ExtractedMesh m;
  DrawRange r;
  r.count = 3;
  r.mode = GL_TRIANGLE_STRIP;
  EXPECT_FALSE(extractMesh(vb, PositionLayout{3, GL_FLOAT, 0, 0}, r, m));
  r.mode = GL_TRIANGLES;
  EXPECT_FALSE(extractMesh(vb, PositionLayout{3, GL_HALF_FLOAT, 0, 0}, r, m));
  r.first = 1;  // reads past the end of the buffer
  EXPECT_FALSE(extractMesh(vb, PositionLayout{3, GL_FLOAT, 0, 0}, r, m));
  EXPECT_EQ(primitiveCount(GL_TRIANGLE_STRIP, 5), 3u);
  EXPECT_EQ(primitiveCount(GL_LINES, 5), 2u);
}

TEST(FinishFrame, FlipsRowsDecodesIdsAndCountsVisiblePixels) {
  RawImages raw;
  raw.width = 2;
  raw.height = 2;
  // Bottom row first: bottom-left, bottom-right, top-left, top-right.
  raw.rgba = {1, 1, 1, 255, 2, 2, 2, 255, 3, 3, 3, 255, 4, 4, 4, 255};
  raw.depth = {0.1f, 0.2f, 0.3f, 0.4f};
  raw.ids = {1, 5, 0, 0, 2, 7, 1, 6};
  CaptureFrame f;
  f.draws.resize(2);
  f.draws[1].index = 1;
  finishFrame(raw, f);
  EXPECT_EQ(f.color_rgb, (std::vector<uint8_t>{3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2}));
  EXPECT_EQ(f.depth_window, (std::vector<float>{0.3f, 0.4f, 0.1f, 0.2f}));
  EXPECT_EQ(f.draw_ids, (std::vector<uint32_t>{2, 1, 1, 0}));
  EXPECT_EQ(f.primitive_ids, (std::vector<uint32_t>{7, 6, 5, 0}));
  EXPECT_EQ(f.draws[0].visible_pixels, 2u);
  EXPECT_EQ(f.draws[1].visible_pixels, 1u);
  EXPECT_EQ(validateFrame(f), "");
}

TEST(FinishFrame, UnpacksDepth24Stencil8) {
  RawImages raw;
  raw.width = 1;
  raw.height = 2;
  raw.depth_24_8 = {0xFFFFFF00u | 0x12u, (0x800000u << 8) | 0x34u};  // bottom: far plane; top: ~0.5
  CaptureFrame f;
  finishFrame(raw, f);
  ASSERT_EQ(f.depth_window.size(), 2u);
  EXPECT_NEAR(f.depth_window[0], 0x800000 / 16777215.0, 1e-7);
  EXPECT_EQ(f.depth_window[1], 1.0f);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
