// Mesh extraction from shadow buffers.
#include "mesh_extract.h"
#include "viper/capture/content_key.h"

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

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
