// The synthetic frames of the training-format fixture (docs/training_formats.md, "Validation"):
// write_training_format_cases writes them in every format, scripts/training_formats_reference.sh
// runs the formats' reference code on those files into test/dataset/data/training_formats, and
// test_training_formats checks that the package's writers still produce what the reference read.
#pragma once

#include "viper/dataset/coco.h"
#include "viper/dataset/flow_image.h"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
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

/// The frame's flow as the writers take it.
inline viper::dataset::FlowImage trainingFormatFlow(const TrainingFormatFrame& frame) {
  viper::dataset::FlowImage flow;
  flow.width = TrainingFormatFrame::kWidth;
  flow.height = TrainingFormatFrame::kHeight;
  flow.uv = frame.flow_uv;
  return flow;
}

/// The COCO categories of the fixture: VIPER's instance classes (config/viper_classes.csv,
/// instance_eval 1); the traffic sign's instance is left out.
inline std::vector<std::pair<int, const char*>> trainingFormatCategories() {
  return {{13, "trafficlight"}, {16, "firehydrant"}, {17, "chair"}, {19, "trashcan"}, {20, "person"},
          {23, "motorcycle"}, {24, "car"}, {25, "van"}, {26, "bus"}, {27, "truck"}};
}

/// An amodal object of frame `f`: its whole rectangle (x, y, width, height in px, possibly beyond
/// the image), class and instance id. The car's is partly hidden by the van; the truck's runs past
/// the image's right and bottom borders.
struct AmodalRectangle {
  int x, y;
  uint32_t width, height;
  int class_id;
  int32_t instance_id;
};
inline std::vector<AmodalRectangle> trainingFormatAmodal(int f) {
  return {{4 * (2 + f), 36, 28, 20, 24, 7}, {4 * (6 + f), 32, 24, 20, 25, 3}, {84, 44, 24, 28, 27, 40000}};
}

/// The fixture's COCO files: visible instances, and the amodal rectangles with two more masks on
/// an image of their own.
inline std::pair<viper::dataset::CocoInstancesWriter, viper::dataset::CocoInstancesWriter> trainingFormatCoco() {
  std::vector<viper::dataset::CocoCategory> categories;
  for (const auto& [id, name] : trainingFormatCategories()) categories.push_back({id, name, "viper"});
  viper::dataset::CocoInstancesWriter visible(categories), amodal(categories);
  constexpr uint32_t W = TrainingFormatFrame::kWidth, H = TrainingFormatFrame::kHeight;
  for (int f = 0; f < 2; ++f) {
    const auto frame = trainingFormatFrame(f);
    const std::string file = "train/img/001/001_0000" + std::to_string(f) + ".png";
    visible.addVisibleInstances(visible.addImage(file, W, H, "001", f), frame.classes.data(), frame.instances.data());
    const int image = amodal.addImage(file, W, H, "001", f);
    for (const auto& r : trainingFormatAmodal(f)) {
      const std::vector<uint8_t> ones(static_cast<size_t>(r.width) * r.height, 1);
      amodal.addAnnotation(image, {r.class_id, r.instance_id,
                                   viper::dataset::cocoRleOfBoxMask(W, H, r.x, r.y, r.width, r.height, ones.data())});
    }
  }
  // Masks of every shape of run: random pixels in a box across the top-left corner (a first run of
  // length 0), and the whole image (one run, no 0s).
  const int image = amodal.addImage("random.png", W, H, "002", 0);
  uint32_t state = 12345;
  std::vector<uint8_t> random(40 * 30);
  for (auto& m : random) m = ((state = state * 1664525u + 1013904223u) >> 28) < 7;
  amodal.addAnnotation(image, {20, 1, viper::dataset::cocoRleOfBoxMask(W, H, -5, -3, 40, 30, random.data())});
  const std::vector<uint8_t> all(static_cast<size_t>(W) * H, 1);
  amodal.addAnnotation(image, {24, 2, viper::dataset::cocoRleOfBoxMask(W, H, 0, 0, W, H, all.data())});
  return {std::move(visible), std::move(amodal)};
}

}  // namespace viper_dataset_test
