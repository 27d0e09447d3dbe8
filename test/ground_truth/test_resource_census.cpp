// ResourceCensus on frames whose pixels are known, and proposeClass's rules.
#include "viper/ground_truth/resource_census.h"

#include <gtest/gtest.h>

using viper::CaptureFrame;
using viper::ResourceKind;

namespace {

// A 10 x 4 frame: draw 0 (mesh 7) on columns 0-5 of rows 0-1 at the far plane; draw 1 (no mesh,
// texture 9) on columns 6-9 of row 3, green; draw 2 (mesh 7 again) on column 0 of row 3.
CaptureFrame frame(uint64_t number) {
  CaptureFrame f;
  f.number = number;
  f.width = 10, f.height = 4;
  f.color_rgb.assign(120, 100);
  f.depth_window.assign(40, 0.5f);
  f.draw_ids.assign(40, 0);
  f.draws.resize(3);
  f.draws[0].mesh_key = 7;
  f.draws[1].texture_keys = {0, 9};
  f.draws[1].program_key = 5;
  f.draws[2].mesh_key = 7;
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 6; ++x) f.draw_ids[y * 10 + x] = 1, f.depth_window[y * 10 + x] = 1.0f;
  for (uint32_t x = 6; x < 10; ++x) {
    f.draw_ids[30 + x] = 2;
    f.color_rgb[(30 + x) * 3] = 20, f.color_rgb[(30 + x) * 3 + 1] = 200, f.color_rgb[(30 + x) * 3 + 2] = 20;
  }
  f.draw_ids[30] = 3;
  return f;
}

}  // namespace

TEST(ResourceCensus, CountsPixelsPerResourceAndKeepsTheBestSightings) {
  viper::ResourceCensus census(1);
  viper::MeshRegistry meshes;
  census.add(frame(4), meshes);
  CaptureFrame g = frame(5);
  for (uint32_t x = 0; x < 6; ++x) g.draw_ids[10 + x] = 0;  // frame 5 shows less of mesh 7
  census.add(g, meshes);
  const auto r = census.resources();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].kind, ResourceKind::kMesh);
  EXPECT_EQ(r[0].key, 7u);
  EXPECT_EQ(r[0].pixels, 13u + 7u);  // both draws of mesh 7, both frames
  EXPECT_EQ(r[0].frames, 2u);
  EXPECT_EQ(r[0].far_pixels, 12u + 6u);
  ASSERT_EQ(r[0].best.size(), 1u);
  EXPECT_EQ(r[0].best[0].frame, 4u);
  EXPECT_EQ(r[0].best[0].x0, 0u);
  EXPECT_EQ(r[0].best[0].y1, 3u);  // its pixels span rows 0-3 (draw 2 on row 3)
  EXPECT_EQ(r[1].kind, ResourceKind::kTexture);  // no mesh: the first non-zero texture
  EXPECT_EQ(r[1].key, 9u);
  EXPECT_EQ(r[1].pixels, 8u);
  EXPECT_EQ(census.totalPixels(), 28u);
}

TEST(ResourceCensus, ProposalsAndThePreviousTable) {
  viper::ResourceCensus census;
  viper::MeshRegistry meshes;
  census.add(frame(0), meshes);
  const auto r = census.resources();
  EXPECT_EQ(viper::proposeClass(r[0]).class_id, 2u) << "12 of 13 pixels at the far plane: the sky";
  EXPECT_EQ(viper::proposeClass(r[1]).class_id, 8u);
  EXPECT_EQ(viper::proposeClass(r[1]).reason, "mostly green");
  viper::LabelTable previous;
  previous.setTexture(9, 24);
  EXPECT_EQ(viper::proposeClass(r[1], &previous).class_id, 24u);
  EXPECT_EQ(viper::proposeClass(r[1], &previous).reason, "the previous label table");

  viper::ResourceStats s;
  s.pixels = 100;
  s.far_pixels = 95;
  EXPECT_EQ(viper::proposeClass(s).class_id, 2u);
  s.far_pixels = 0;
  s.deformed_pixels = 60;
  EXPECT_EQ(viper::proposeClass(s).class_id, 20u);
  s.deformed_pixels = 0;
  s.placed_size = Eigen::Vector3d(40, 0.5, 30);
  EXPECT_EQ(viper::proposeClass(s).class_id, 3u);
  s.placed_size = Eigen::Vector3d(0.3, 6, 0.3);
  EXPECT_EQ(viper::proposeClass(s).class_id, 10u);
  s.placed_size = Eigen::Vector3d(10, 12, 8);
  EXPECT_EQ(viper::proposeClass(s).class_id, 9u);
  s.placed_size = Eigen::Vector3d(2, 1.5, 4);
  EXPECT_EQ(viper::proposeClass(s).class_id, 0u);
}
