// A small dataset in VIPER's layout for the player tests, written by make_viper_test_layout and
// checked by viper_layout_tester: what every file holds, and the damage done to some of them.
//
// <root>/train, 64x48 pixels:
//   sequence 001, frames 0..7: img, cls, inst, flow (0..6), flowbw (1..7), bb, camera (absolute view
//     matrices: the camera drives 0.5 m forward and turns 0.02 rad left per frame), img 7 as JPEG;
//   sequence 002, frames 0..3: img, cls, camera only (any subset of modalities).
// Damage (each must be reported naming its file, the rest still played):
//   001 img 2 missing; cls 3 is 32x48; flow 4 has a flipped byte; inst 5 is truncated; bb 6 has a
//   line of 5 values after its good line; camera line of frame 6 holds a word; flowbw 1 is text;
//   a stray img/001/README.txt; 002 cls 1 is text.
#pragma once

#include "../common/rgb_image.h"

#include "viper/dataset/flow_image.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/dataset/viper_images.h"

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace viper_test_layout {

using viper::dataset::FlowImage;
using viper::dataset::Image8;
using viper::dataset::RowMajor4;
using viper::dataset::ViperBoxRow;

constexpr uint32_t kWidth = 64, kHeight = 48;
constexpr uint64_t kFrames001 = 8, kFrames002 = 4;
constexpr double kStepM = 0.5, kYawRad = 0.02;
constexpr int kCarClass = 24, kCarId = 7;

inline Image8 colorImage(int seq, uint64_t frame) {
  return viper::test::rgbImage(kWidth, kHeight, [&](uint32_t x, uint32_t y) {
    return std::array<uint8_t, 3>{static_cast<uint8_t>(4 * x), static_cast<uint8_t>(5 * y),
                                  static_cast<uint8_t>(30 * frame + 60 * seq)};
  });
}

inline Image8 classImage(int seq, uint64_t frame, uint32_t width = kWidth) {
  Image8 im;
  im.width = width, im.height = kHeight, im.channels = 1;
  im.data.resize(im.pixels());
  for (uint32_t y = 0; y < kHeight; ++y)
    for (uint32_t x = 0; x < width; ++x) im.data[y * width + x] = static_cast<uint8_t>((x / 8 + y / 12 + frame + seq) % 32);
  return im;
}

/// R = a class different from classImage's (so the semantic fallback to inst's R is visible),
/// instance 256 * G + B = 300 + x / 16 on the left half, 0 elsewhere.
inline Image8 instanceImage(uint64_t frame) {
  return viper::test::rgbImage(kWidth, kHeight, [&](uint32_t x, uint32_t) {
    const int id = x < kWidth / 2 ? 300 + static_cast<int>(x / 16 + frame) : 0;
    return std::array<uint8_t, 3>{static_cast<uint8_t>(x < kWidth / 2 ? kCarClass : 3), static_cast<uint8_t>(id / 256),
                                  static_cast<uint8_t>(id % 256)};
  });
}

/// Values on a 1/4 px grid below 64 px: exact in float16.
inline FlowImage flowImage(uint64_t frame, bool backward) {
  FlowImage f;
  f.width = kWidth, f.height = kHeight;
  f.uv.resize(2 * f.pixels());
  const float sign = backward ? -1.0f : 1.0f;
  for (size_t i = 0; i < f.pixels(); ++i) {
    f.uv[2 * i] = sign * (0.25f * static_cast<float>(frame) + 0.5f * static_cast<float>(i % 4));
    f.uv[2 * i + 1] = -0.25f * static_cast<float>(i % 3);
  }
  if (!backward) f.uv[0] = NAN;  // invalid flow at the top-left pixel
  return f;
}

/// OpenGL projection: 60 degree vertical field of view, aspect 4:3, near 0.1, far 500.
inline RowMajor4 projection() {
  const double f = 1.0 / std::tan(M_PI / 6), near = 0.1, far = 500.0;
  RowMajor4 p{};
  p[0] = f * kHeight / kWidth;
  p[5] = f;
  p[10] = -(far + near) / (far - near);
  p[11] = -2 * far * near / (far - near);
  p[14] = -1;
  return p;
}

/// World -> OpenGL camera at frame n: camera at (0, 1.5, -0.5 n), turned 0.02 n rad about +Y.
inline RowMajor4 view(uint64_t frame) {
  const double a = kYawRad * static_cast<double>(frame), c = std::cos(a), s = std::sin(a);
  // world_from_camera = T(p) * Ry(a); view = Ry(-a) * T(-p).
  const double px = 0, py = 1.5, pz = -kStepM * static_cast<double>(frame);
  RowMajor4 v{};
  v[0] = c, v[1] = 0, v[2] = -s;
  v[4] = 0, v[5] = 1, v[6] = 0;
  v[8] = s, v[9] = 0, v[10] = c;
  v[3] = -(v[0] * px + v[1] * py + v[2] * pz);
  v[7] = -(v[4] * px + v[5] * py + v[6] * pz);
  v[11] = -(v[8] * px + v[9] * py + v[10] * pz);
  v[15] = 1;
  return v;
}

/// One car 10 m ahead and 1 m right, turned 30 degrees about the camera's up axis, model scaled by
/// 1.5: in the optical frame its centre is (1, 0, 10) and its size (3, 1.5, 6).
inline ViperBoxRow carBox(uint64_t frame) {
  ViperBoxRow row;
  row.class_id = kCarClass;
  row.instance_id = kCarId;
  row.box_2d = {{2.0 + frame, 3, 20, 30}};
  row.box_3d = {{-1, -0.5, -2, 1, 0.5, 2}};
  const double a = M_PI / 6, c = std::cos(a) * 1.5, s = std::sin(a) * 1.5;
  row.model_to_camera = {{c, 0, s, 1, 0, 1.5, 0, 0, -s, 0, c, -10, 0, 0, 0, 1}};
  return row;
}

}  // namespace viper_test_layout
