// The synthetic frames of the training-format fixture (docs/training_formats.md, "Validation"):
// write_training_format_cases writes them in every format, scripts/training_formats_reference.sh
// runs the formats' reference code on those files into test/dataset/data/training_formats, and
// test_training_formats checks that the package's writers still produce what the reference read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace viper_dataset_test {

/// One frame of VIPER ground truth: class ids and instance ids per pixel, and flow and depth.
struct TrainingFormatFrame {
  static constexpr uint32_t kWidth = 96, kHeight = 64;
  std::vector<uint8_t> classes = std::vector<uint8_t>(kWidth * kHeight);
  std::vector<int32_t> instances = std::vector<int32_t>(kWidth * kHeight);
  std::vector<float> flow_uv = std::vector<float>(2 * kWidth * kHeight);  ///< NaN: no flow
  std::vector<float> depth_m = std::vector<float>(kWidth * kHeight);      ///< NaN: no depth
};

/// Frame `f` (0 or 1; objects move by 4 f px): sky, building, an 'infrastructure' pole, road and
/// sidewalk; a car (instance 7), a van (instance 3, also Cityscapes' 'car') overlapping it, a person
/// (instance 12) with a few person pixels without instance (a group), a truck with a 16-bit instance
/// id (40000), a traffic sign with an instance id (dropped by Cityscapes), a trash pixel (Cityscapes
/// 'dynamic'). Flow: a ramp with exact and rounded values, NaN in a corner; depth: a ramp, NaN in
/// the sky.
inline TrainingFormatFrame trainingFormatFrame(int f) {
  constexpr int W = TrainingFormatFrame::kWidth, H = TrainingFormatFrame::kHeight;
  TrainingFormatFrame frame;
  // Rectangles on a grid of 4 px cells (Cityscapes' instance evaluation ignores instances under
  // 100 px).
  auto fill = [&](int x0, int y0, int x1, int y1, uint8_t cls, int32_t inst) {
    for (int y = 4 * y0; y < 4 * y1; ++y)
      for (int x = 4 * x0; x < 4 * x1; ++x) {
        if (x < 0 || x >= W || y < 0 || y >= H) continue;
        frame.classes[y * W + x] = cls;
        frame.instances[y * W + x] = inst;
      }
  };
  fill(0, 0, 24, 4, 2, 0);      // sky
  fill(0, 4, 24, 8, 9, 0);      // building
  fill(0, 8, 24, 12, 4, 0);     // sidewalk
  fill(0, 12, 24, 16, 3, 0);     // road
  fill(20, 2, 21, 12, 10, 0);  // infrastructure (a pole)
  fill(2 + f, 9, 9 + f, 14, 24, 7);    // car
  fill(6 + f, 8, 12 + f, 13, 25, 3);   // van, in front of the car's right side
  fill(14, 6 - f, 16, 13 - f, 20, 12);  // person
  fill(17, 10, 18, 13, 20, 0);          // person pixels without instance (a group)
  fill(21, 11, 24, 16, 27, 40000);      // truck (cut by the image's border)
  fill(1, 5, 3, 7, 14, 5);              // traffic sign with an instance id
  fill(12, 15, 13, 16, 18, 0);          // trash
  frame.classes[0] = 0;                 // an unlabeled pixel
  frame.instances[0] = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      // u: multiples of 1/64 px (exact in KITTI's encoding) and values between them.
      frame.flow_uv[2 * i] = static_cast<float>(x - 48) * 0.3125f + static_cast<float>(f) * 0.3f;
      frame.flow_uv[2 * i + 1] = static_cast<float>(y - 32) * -0.7f + (x % 3 == 0 ? 1.0f / 64 : 0.01f);
      frame.depth_m[i] = frame.classes[i] == 2 ? std::numeric_limits<float>::quiet_NaN()
                                               : 2.0f + 0.09f * static_cast<float>(x) + 2.7f * static_cast<float>(y);
    }
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) frame.flow_uv[2 * (y * W + x)] = std::numeric_limits<float>::quiet_NaN();
  frame.flow_uv[2 * (5 * W + 7) + 1] = std::numeric_limits<float>::infinity();
  frame.flow_uv[2 * (6 * W + 7)] = 600.0f;    // beyond KITTI's range (+-512 px): no flow there
  frame.depth_m[40 * W + 50] = 300.0f;         // beyond KITTI's range (256 m): no depth there
  return frame;
}

}  // namespace viper_dataset_test
