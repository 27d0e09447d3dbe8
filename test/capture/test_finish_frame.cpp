// Frame finishing (row flip, id decoding, visible pixels): fixed cases, and the vectorised path
// against the one-pixel-at-a-time reference on every kind of pixel.
#include "finish_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

using namespace viper;
using namespace viper::capture;

namespace {

TEST(FinishFrame, FlipsRowsDecodesIdsAndCountsVisiblePixels) {
  RawImages raw;
  raw.width = 2;
  raw.height = 2;
  // Bottom row first: bottom-left, bottom-right, top-left, top-right.
  raw.rgba = {1, 1, 1, 255, 2, 2, 2, 255, 3, 3, 3, 255, 4, 4, 4, 255};
  raw.depth = {0.1f, 0.2f, 0.3f, 0.4f};
  raw.ids = {1, 5, 0, 0, 2, 7, 1, 6};
  CaptureFrame f;
  f.draws.resize(2);
  f.draws[1].index = 1;
  finishFrame(raw, f);
  EXPECT_EQ(f.color_rgb, (std::vector<uint8_t>{3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2}));
  EXPECT_EQ(f.depth_window, (std::vector<float>{0.3f, 0.4f, 0.1f, 0.2f}));
  EXPECT_EQ(f.draw_ids, (std::vector<uint32_t>{2, 1, 1, 0}));
  EXPECT_EQ(f.primitive_ids, (std::vector<uint32_t>{7, 6, 5, 0}));
  EXPECT_EQ(f.draws[0].visible_pixels, 2u);
  EXPECT_EQ(f.draws[1].visible_pixels, 1u);
  EXPECT_EQ(validateFrame(f), "");
}

TEST(FinishFrame, UnpacksDepth24Stencil8) {
  RawImages raw;
  raw.width = 1;
  raw.height = 2;
  raw.depth_24_8 = {0xFFFFFF00u | 0x12u, (0x800000u << 8) | 0x34u};  // bottom: far plane; top: ~0.5
  CaptureFrame f;
  finishFrame(raw, f);
  ASSERT_EQ(f.depth_window.size(), 2u);
  EXPECT_NEAR(f.depth_window[0], 0x800000 / 16777215.0, 1e-7);
  EXPECT_EQ(f.depth_window[1], 1.0f);
}

// Read-back images of w x h pixels whose draw ids run in spans (as objects do) broken by every
// kind of bad id: 0, NaN, infinities, negative, fractional, beyond the draw count; primitive ids
// likewise (NaN, negative, huge).
RawImages mixedImages(int w, int h, uint32_t draws, bool packed_depth, std::mt19937& rng) {
  RawImages raw;
  raw.width = w;
  raw.height = h;
  const size_t n = static_cast<size_t>(w) * h;
  raw.rgba.resize(n * 4);
  for (auto& b : raw.rgba) b = static_cast<uint8_t>(rng());
  if (packed_depth) {
    raw.depth_24_8.resize(n);
    for (auto& d : raw.depth_24_8) d = static_cast<uint32_t>(rng());
  } else {
    raw.depth.resize(n);
    for (auto& d : raw.depth) d = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float bad_ids[] = {0.0f, nan, inf, -inf, -3.0f, 0.4f, 0.99f, static_cast<float>(draws) + 1.0f, 1e9f};
  const float bad_primitives[] = {nan, -1.0f, -inf, inf, 3e9f, 1e20f, 0.49f};
  raw.ids.resize(n * 2);
  float id = 1.0f;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t r = rng() % 100;
    if (r < 8) id = static_cast<float>(1 + rng() % draws);  // a new span
    float this_id = id, primitive = static_cast<float>(rng() % 5000);
    if (r == 8) this_id = bad_ids[rng() % (sizeof(bad_ids) / sizeof(float))];
    if (r == 9) primitive = bad_primitives[rng() % (sizeof(bad_primitives) / sizeof(float))];
    if (r == 10) this_id += 0.3f;  // rounds to the same draw
    raw.ids[2 * i] = this_id;
    raw.ids[2 * i + 1] = primitive;
  }
  return raw;
}

// A frame of `n` draws, indexed as a capture indexes them.
CaptureFrame frameOf(uint32_t n) {
  CaptureFrame f;
  f.draws.resize(n);
  for (uint32_t i = 0; i < n; ++i) f.draws[i].index = i;
  return f;
}

void expectSameFrames(const CaptureFrame& a, const CaptureFrame& b) {
  EXPECT_EQ(a.color_rgb, b.color_rgb);
  EXPECT_EQ(0, std::memcmp(a.depth_window.data(), b.depth_window.data(), a.depth_window.size() * sizeof(float)));
  EXPECT_EQ(a.depth_window.size(), b.depth_window.size());
  EXPECT_EQ(a.draw_ids, b.draw_ids);
  EXPECT_EQ(a.primitive_ids, b.primitive_ids);
  ASSERT_EQ(a.draws.size(), b.draws.size());
  for (size_t i = 0; i < a.draws.size(); ++i) EXPECT_EQ(a.draws[i].visible_pixels, b.draws[i].visible_pixels) << i;
}

TEST(FinishFrame, VectorisedPathEqualsTheReferenceOnEveryKindOfPixel) {
  std::mt19937 rng(7);
  // Widths around the block size and the row end (the color stores run 4 bytes past a block).
  for (int w : {1, 7, 8, 9, 10, 11, 16, 17, 18, 25, 640, 1923}) {
    for (bool packed : {false, true}) {
      const uint32_t draws = 1 + rng() % 300;
      const RawImages raw = mixedImages(w, 13, draws, packed, rng);
      CaptureFrame fast = frameOf(draws), reference = frameOf(draws);
      finishFrame(raw, fast);
      finishFrameScalar(raw, reference);
      SCOPED_TRACE("width " + std::to_string(w) + (packed ? " packed depth" : " float depth"));
      expectSameFrames(fast, reference);
      uint64_t counted = 0;
      for (const DrawRecord& d : fast.draws) counted += d.visible_pixels;
      uint64_t with_draw = 0;
      for (uint32_t id : fast.draw_ids) with_draw += id != 0;
      EXPECT_EQ(counted, with_draw);
      if (w >= 640) {
        EXPECT_GT(with_draw, raw.ids.size() / 2 * 9 / 10);  // most pixels show a draw
        EXPECT_LT(with_draw, raw.ids.size() / 2);           // and the bad ids were dropped
      }
      EXPECT_EQ(validateFrame(fast), "");
    }
  }
}

// Regression (wined3d): depth and ids of a framebuffer object the program shows upside down are
// read top row first, the colour of the window bottom row first; all come out top row first.
TEST(FinishFrame, DepthAndIdsTopRowFirstFromAFlippedScene) {
  RawImages raw;
  raw.width = 2;
  raw.height = 2;
  raw.depth_ids_top_first = true;
  raw.rgba = {1, 1, 1, 255, 2, 2, 2, 255, 3, 3, 3, 255, 4, 4, 4, 255};  // bottom row first
  raw.depth = {0.3f, 0.4f, 0.1f, 0.2f};                                  // top row first
  raw.ids = {2, 7, 1, 6, 1, 5, 0, 0};
  for (bool vectorised : {true, false}) {
    CaptureFrame f;
    f.draws.resize(2);
    f.draws[1].index = 1;
    vectorised ? finishFrame(raw, f) : finishFrameScalar(raw, f);
    EXPECT_EQ(f.color_rgb, (std::vector<uint8_t>{3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2}));
    EXPECT_EQ(f.depth_window, (std::vector<float>{0.3f, 0.4f, 0.1f, 0.2f}));
    EXPECT_EQ(f.draw_ids, (std::vector<uint32_t>{2, 1, 1, 0}));
    EXPECT_EQ(f.primitive_ids, (std::vector<uint32_t>{7, 6, 5, 0}));
    EXPECT_EQ(f.draws[0].visible_pixels, 2u);
  }
  // Packed depth likewise, and the vectorised path equals the reference on wide rows.
  std::mt19937 rng(11);
  for (bool packed : {false, true}) {
    RawImages wide = mixedImages(37, 5, 40, packed, rng);
    wide.depth_ids_top_first = true;
    CaptureFrame fast = frameOf(40), reference = frameOf(40);
    finishFrame(wide, fast);
    finishFrameScalar(wide, reference);
    expectSameFrames(fast, reference);
    const size_t w = 37;
    for (size_t y = 0; y < 5; ++y) {
      const float id = wide.ids[2 * y * w];  // row y of the read-back is row y of the frame
      EXPECT_EQ(fast.draw_ids[y * w], id >= 1.0f && id <= 40.0f ? static_cast<uint32_t>(id + 0.5f) : 0u) << y;
    }
  }
}

TEST(FinishFrame, MissingImagesGiveBlackFarAndNoDraws) {
  std::mt19937 rng(3);
  RawImages raw = mixedImages(37, 5, 4, false, rng);
  raw.rgba.clear();
  raw.depth.clear();
  raw.ids.clear();
  CaptureFrame fast = frameOf(4), reference = frameOf(4);
  finishFrame(raw, fast);
  finishFrameScalar(raw, reference);
  expectSameFrames(fast, reference);
  EXPECT_EQ(fast.color_rgb, std::vector<uint8_t>(37 * 5 * 3, 0));
  EXPECT_EQ(fast.depth_window, std::vector<float>(37 * 5, 1.0f));
  EXPECT_EQ(fast.draw_ids, std::vector<uint32_t>(37 * 5, 0));
  for (const DrawRecord& d : fast.draws) EXPECT_EQ(d.visible_pixels, 0u);
}

TEST(FinishFrame, RecycledFrameMemoryIsFullyOverwritten) {
  std::mt19937 rng(5);
  const RawImages first = mixedImages(64, 9, 20, false, rng), second = mixedImages(64, 9, 20, true, rng);
  CaptureFrame reused = frameOf(20), fresh = frameOf(20);
  finishFrame(first, reused);
  finishFrame(second, reused);
  finishFrameScalar(second, fresh);
  expectSameFrames(reused, fresh);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
