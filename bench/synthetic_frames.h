// Synthetic 1920x1080 frames for benchmarks: many objects of several parts tiling the image,
// smooth depth, rigid motion between two frames. Shapes only; values are not ground truth.
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/label_table.h"

#include <Eigen/Geometry>

#include <cmath>

namespace viper {
namespace bench {

inline GlMatrix benchProjection(uint32_t w, uint32_t h) {
  GlMatrix p = GlMatrix::Zero();
  const float t = 1.0f / std::tan(0.5f), n = 0.1f, f = 500.f;
  p(0, 0) = t * h / w, p(1, 1) = t, p(2, 2) = -(f + n) / (f - n), p(2, 3) = -2 * f * n / (f - n), p(3, 2) = -1;
  return p;
}

/// A frame of `objects` objects with `parts` draws each, laid out as a grid of tiles; one draw in
/// `deformed_every` is deformed (0 = none). Frame `step` moves every object a little.
inline CaptureFrame syntheticFrame(uint32_t w, uint32_t h, int objects, int parts, int step, LabelTable* labels,
                                   int deformed_every = 0) {
  CaptureFrame f;
  f.width = w, f.height = h, f.number = step, f.time_s = step / 15.0;
  const GlMatrix proj = benchProjection(w, h);
  GlMatrix view = GlMatrix::Identity();
  view(0, 3) = -0.05f * step;
  const int cols = static_cast<int>(std::ceil(std::sqrt(objects * 16.0 / 9.0)));
  const int rows = (objects + cols - 1) / cols;
  for (int o = 0; o < objects; ++o) {
    GlMatrix world = GlMatrix::Identity();
    world(0, 3) = (o % cols) * 3.0f + 0.02f * step;
    world(1, 3) = (o / cols) * 2.0f;
    world(2, 3) = -20.0f - o % 7;
    for (int p = 0; p < parts; ++p) {
      DrawRecord d;
      d.index = static_cast<uint32_t>(f.draws.size());
      d.mesh_key = 1000 + (o % 5) * 10 + p;
      d.program_key = 7;
      d.matrix_flags = kHasWorld | kHasView | kHasProjection;
      d.world = world, d.view = view, d.projection = proj;
      d.primitive_count = 12;
      d.visible_pixels = 1000;
      if (deformed_every > 0 && d.index % deformed_every == 0) {
        for (int v = 0; v < 8; ++v) {
          const Eigen::Vector4f c = proj * view * world * Eigen::Vector4f((v & 1) * 2.f - 1, (v & 2) - 1.f, (v & 4) * .5f - 1, 1);
          d.deformed_clip_xyzw.insert(d.deformed_clip_xyzw.end(), {c.x(), c.y(), c.z(), c.w()});
        }
      }
      f.draws.push_back(d);
      if (labels && step == 0) labels->setMesh(d.mesh_key, static_cast<uint8_t>(p == 0 ? 24 + o % 4 : 24));
    }
  }
  const size_t n = f.pixelCount();
  f.draw_ids.resize(n), f.primitive_ids.resize(n), f.depth_window.resize(n), f.color_rgb.assign(3 * n, 90);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const int tile = static_cast<int>(y * rows / h) * cols + static_cast<int>(x * cols / w);
      const size_t i = static_cast<size_t>(y) * w + x;
      const int o = tile % objects;
      f.draw_ids[i] = 1 + o * parts + static_cast<int>((x + y) / 8) % parts;
      f.primitive_ids[i] = (x / 16 + y / 16) % 12;
      f.depth_window[i] = 0.995f + 0.004f * y / h;
    }
  return f;
}

/// The 8-vertex, 12-triangle box every synthetic mesh key stands for.
inline MeshRecord syntheticMesh(uint64_t key) {
  MeshRecord m;
  m.key = key;
  for (int v = 0; v < 8; ++v) m.positions_xyz.insert(m.positions_xyz.end(), {(v & 1) * 2.f - 1, (v & 2) - 1.f, (v & 4) * .5f - 1});
  m.indices = {0, 1, 3, 0, 3, 2, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 3, 7, 1, 7, 5};
  return m;
}

}  // namespace bench
}  // namespace viper
