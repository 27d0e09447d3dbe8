// Draw messages of the bad-input testers (bad_input_tester.cpp, flow_bad_input_tester.cpp), which
// make their frames by hand.
#pragma once

#include <viper/Draw.h>

#include <cstdint>

namespace viper {
namespace test {

/// Draw `index` of mesh `mesh`, moved to x = `x` in the world (metres), seen by a camera 10 m from
/// the z = 0 plane looking at it (identity view otherwise, a fixed perspective projection), owning
/// `visible_pixels` pixels of the draw ids image.
inline viper::Draw draw(uint32_t index, uint64_t mesh, float x, uint32_t visible_pixels) {
  viper::Draw d;
  d.index = index;
  d.mesh_key = mesh;
  d.matrix_flags = viper::Draw::HAS_WORLD | viper::Draw::HAS_VIEW | viper::Draw::HAS_PROJECTION;
  for (int i = 0; i < 16; ++i) d.world[i] = d.view[i] = (i % 5 == 0) ? 1.0f : 0.0f;
  d.world[12] = x;
  d.view[14] = -10.0f;
  d.projection = {1.5f, 0, 0, 0, 0, 2, 0, 0, 0, 0, -1.0004f, -1, 0, 0, -0.20004f, 0};
  d.visible_pixels = visible_pixels;
  return d;
}

}  // namespace test
}  // namespace viper
