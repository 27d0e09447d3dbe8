#include "viper/ground_truth/semantic_overlay.h"

#include "../common/vector_paths.h"

#include <gtest/gtest.h>

#include <random>
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

using test::firstDifference;
using test::pathName;

// Class ids in runs of 1..40 (objects), a third of them 0, some beyond the table and up to 255.
std::vector<uint8_t> randomIds(std::mt19937& rng, size_t n, size_t classes) {
  std::vector<uint8_t> ids(n);
  std::uniform_int_distribution<int> run(1, 40), kind(0, 5), in_table(1, static_cast<int>(classes) - 1),
      beyond(static_cast<int>(classes), 255);
  for (size_t i = 0; i < n;) {
    const int k = kind(rng);
    const uint8_t id = static_cast<uint8_t>(k < 2 ? 0 : k < 4 ? in_table(rng) : k == 4 ? beyond(rng) : rng() % 256);
    for (int r = run(rng); r > 0 && i < n; --r) ids[i++] = id;
  }
  return ids;
}

// Every vector path gives the scalar path's bytes, at sizes around the blocks (16, 32, 64 pixels),
// from unaligned pointers, and writes nothing past the n pixels.
TEST(SemanticOverlay, VectorPathsGiveTheScalarBytes) {
  const ClassTable t = ClassTable::load("config/viper_classes.csv");
  const std::vector<Instructions> paths = test::vectorPaths();
  if (paths.empty()) GTEST_SKIP() << "no vector path on this CPU";
  std::mt19937 rng(7);
  constexpr size_t kGuard = 200;
  for (size_t n : {0, 1, 7, 15, 16, 17, 31, 32, 33, 63, 64, 65, 95, 127, 128, 129, 1000, 1921 * 3 + 5, 1920 * 17}) {
    for (int offset : {0, 1, 3}) {
      std::vector<uint8_t> ids_storage = randomIds(rng, n + offset, t.size());
      std::vector<uint8_t> color_storage(3 * (n + offset));
      for (auto& c : color_storage) c = static_cast<uint8_t>(rng());
      const uint8_t* ids = ids_storage.data() + offset;
      const uint8_t* color = color_storage.data() + 3 * offset;

      std::vector<uint8_t> want(3 * n + kGuard, 0xa5), got(3 * n + kGuard + offset);
      colorizeClasses(ids, n, t, want.data(), Instructions::kScalar);
      for (Instructions path : paths) {
        std::fill(got.begin(), got.end(), 0xa5);
        colorizeClasses(ids, n, t, got.data() + offset, path);
        EXPECT_EQ(firstDifference(want.data(), got.data() + offset, want.size()), -1)
            << "colorize " << pathName(path) << " n " << n << " offset " << offset;
      }
      for (float alpha : {0.0f, 0.5f, 1.0f, 0.3f, 0.999f, 0.001f, -0.5f, 1.5f}) {
        std::fill(want.begin(), want.end(), 0xa5);
        overlayClasses(color, ids, n, t, alpha, want.data(), Instructions::kScalar);
        for (Instructions path : paths) {
          std::fill(got.begin(), got.end(), 0xa5);
          overlayClasses(color, ids, n, t, alpha, got.data() + offset, path);
          EXPECT_EQ(firstDifference(want.data(), got.data() + offset, want.size()), -1)
              << "overlay " << pathName(path) << " n " << n << " offset " << offset << " alpha " << alpha;
        }
      }
    }
  }
  // Every class id and every color byte against every palette byte, at alpha 0.5 and 1/3.
  const size_t n = 256 * 256;
  std::vector<uint8_t> ids(n), color(3 * n), want(3 * n), got(3 * n);
  for (size_t i = 0; i < n; ++i) {
    ids[i] = static_cast<uint8_t>(i % 256);
    color[3 * i] = color[3 * i + 1] = color[3 * i + 2] = static_cast<uint8_t>(i / 256);
  }
  for (float alpha : {0.5f, 1.0f / 3.0f}) {
    overlayClasses(color.data(), ids.data(), n, t, alpha, want.data(), Instructions::kScalar);
    for (Instructions path : paths) {
      overlayClasses(color.data(), ids.data(), n, t, alpha, got.data(), path);
      EXPECT_EQ(firstDifference(want.data(), got.data(), want.size()), -1) << "overlay " << pathName(path);
    }
  }
}

}  // namespace
}  // namespace viper
