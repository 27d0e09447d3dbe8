#include "viper/ground_truth/semantic_overlay.h"

#include <gtest/gtest.h>

#include <vector>

namespace viper {
namespace {

TEST(SemanticOverlay, ColorsAndBlend) {
  const ClassTable t = ClassTable::load("config/viper_classes.csv");
  const std::vector<uint8_t> ids = {24, 0, 3, 200};
  std::vector<uint8_t> rgb(12);
  colorizeClasses(ids.data(), ids.size(), t, rgb.data());
  EXPECT_EQ(rgb, (std::vector<uint8_t>{0, 0, 142, 0, 0, 0, 128, 64, 128, 0, 0, 0}));
  const std::vector<uint8_t> cam = {200, 100, 50, 10, 20, 30, 0, 0, 0, 255, 255, 255};
  std::vector<uint8_t> out(12);
  overlayClasses(cam.data(), ids.data(), ids.size(), t, 0.5f, out.data());
  EXPECT_EQ(out[0], 100);   // (200 + 0) / 2
  EXPECT_EQ(out[2], 96);    // (50 + 142) / 2
  EXPECT_EQ(out[3], 10);    // unlabeled keeps the camera color
  EXPECT_EQ(out[6], 64);    // road over black
  overlayClasses(cam.data(), ids.data(), ids.size(), t, 0.0f, out.data());
  EXPECT_EQ(out, cam);
  overlayClasses(cam.data(), ids.data(), 3, t, 1.0f, out.data());
  EXPECT_EQ(out[2], 142);
}

}  // namespace
}  // namespace viper
