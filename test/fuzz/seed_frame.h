// The captured frame the seeds are made of: small, but with every part of a frame filled.
#pragma once

#include "viper/capture/capture_frame.h"

namespace viper::fuzz {

/// A 4x3 frame numbered `number` with two draws (one deformed) and one new mesh.
inline CaptureFrame seedFrame(uint64_t number) {
  CaptureFrame f;
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
    DrawRecord d;
    d.index = i;
    d.mesh_key = 10 + i;
    d.texture_keys = {77};
    d.matrix_flags = kHasWorld;
    d.primitive_count = 2;
    if (i == 1) d.deformed_clip_xyzw = {0, 0, 0.5f, 1, 1, 0, 0.5f, 1, 0, 1, 0.5f, 1};
    f.draws.push_back(d);
  }
  MeshRecord m;
  m.key = 10;
  m.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  f.new_meshes.push_back(m);
  return f;
}

}  // namespace viper::fuzz
