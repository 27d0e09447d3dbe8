// Middlebury .flo files: exact round trips, the unknown-flow convention, the bytes on disk, and
// damaged files.
#include "viper/dataset/middlebury_flo.h"

#include "dataset_test_util.h"
#include "flow_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace {

using namespace viper::dataset;
using namespace viper_dataset_test;

constexpr float kInf = std::numeric_limits<float>::infinity();

float f32At(const std::vector<uint8_t>& b, size_t offset) {
  const uint32_t x = b[offset] | b[offset + 1] << 8 | b[offset + 2] << 16 | static_cast<uint32_t>(b[offset + 3]) << 24;
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

FlowImage sample() {
  FlowImage f;
  f.width = 7;
  f.height = 2;
  f.uv = {
      0.0f, -0.0f,             // 0
      1.5f, -2.25f,            // 1
      1e-40f, -1e-45f,         // 2: float subnormals
      123.456f, -987.654f,     // 3
      1e8f, -1e8f,             // 4
      1e9f, -1e9f,             // 5: at the threshold, still known
      0.1f, 0.2f,              // 6
      std::nanf(""), 5.0f,     // 7: u NaN -> pixel unknown
      7.0f, kInf,              // 8: v inf -> unknown
      2e9f, 0.0f,              // 9: |u| > 1e9 -> unknown
      -kInf, -kInf,            // 10
      3.0f, 4.0f,              // 11
      -5.0f, 6.0f,             // 12
      -0.5f, 1e-30f,           // 13
  };
  return f;
}

TEST(MiddleburyFlo, RoundTripKeepsKnownValuesExactly) {
  TempDir dir;
  const FlowImage f = sample();
  ASSERT_EQ(f.uv.size(), 2 * f.pixels());
  writeMiddleburyFlo(dir / "f.flo", f);
  const FlowImage back = readMiddleburyFlo(dir / "f.flo");
  ASSERT_EQ(back.width, 7u);
  ASSERT_EQ(back.height, 2u);
  const std::vector<size_t> unknown_pixels = {7, 8, 9, 10};
  for (size_t p = 0; p < f.pixels(); ++p) {
    const bool unknown = std::find(unknown_pixels.begin(), unknown_pixels.end(), p) != unknown_pixels.end();
    for (size_t c = 0; c < 2; ++c) {
      const float got = back.uv[2 * p + c], in = f.uv[2 * p + c];
      if (unknown) EXPECT_TRUE(std::isnan(got)) << "pixel " << p;
      else {
        uint32_t a, b;
        std::memcpy(&a, &in, 4);
        std::memcpy(&b, &got, 4);
        EXPECT_EQ(a, b) << "pixel " << p << " component " << c << ": " << in << " -> " << got;
      }
    }
  }
}

TEST(MiddleburyFlo, BytesFollowTheFormat) {
  TempDir dir;
  writeMiddleburyFlo(dir / "f.flo", sample());
  const std::vector<uint8_t> b = readBytes(dir / "f.flo");
  ASSERT_EQ(b.size(), 12u + 8 * 14);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "PIEH");
  EXPECT_EQ(f32At(b, 0), 202021.25f);
  EXPECT_EQ(b[4] | b[5] << 8 | b[6] << 16 | b[7] << 24, 7);
  EXPECT_EQ(b[8] | b[9] << 8 | b[10] << 16 | b[11] << 24, 2);
  EXPECT_EQ(f32At(b, 12 + 8 * 1), 1.5f);      // u of pixel 1
  EXPECT_EQ(f32At(b, 12 + 8 * 1 + 4), -2.25f);  // v of pixel 1
  for (size_t p : {7, 8, 9, 10}) {
    EXPECT_EQ(f32At(b, 12 + 8 * p), 1e10f) << "unknown pixel " << p;
    EXPECT_EQ(f32At(b, 12 + 8 * p + 4), 1e10f) << "unknown pixel " << p;
  }
}

TEST(MiddleburyFlo, WriterRejectsInconsistentFlow) {
  TempDir dir;
  FlowImage f = sample();
  f.uv.pop_back();
  EXPECT_THROW(writeMiddleburyFlo(dir / "x.flo", f), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.flo"));
  const std::string path = dir / "missing/x.flo";
  expectErrorNaming([&] { writeMiddleburyFlo(path, sample()); }, {path}, "missing folder");
}

TEST(MiddleburyFlo, DamagedFilesGiveErrorsNamingTheFileAndOffset) {
  TempDir dir;
  writeMiddleburyFlo(dir / "good.flo", sample());
  const std::vector<uint8_t> good = readBytes(dir / "good.flo");
  auto variant = [&](const std::string& name, std::vector<uint8_t> bytes) {
    const std::string path = dir / name;
    writeBytes(path, bytes);
    return path;
  };
  auto withInt = [&](size_t offset, int32_t v) {
    std::vector<uint8_t> b = good;
    for (int i = 0; i < 4; ++i) b[offset + i] = static_cast<uint8_t>(static_cast<uint32_t>(v) >> (8 * i));
    return b;
  };

  const std::string missing = dir / "none.flo";
  expectErrorNaming([&] { readMiddleburyFlo(missing); }, {missing}, "missing");
  const std::string tiny = variant("tiny.flo", {'P', 'I', 'E', 'H', 1});
  expectErrorNaming([&] { readMiddleburyFlo(tiny); }, {tiny, "12-byte", "offset 5"}, "short header");
  std::vector<uint8_t> tag = good;
  tag[3] = 'X';
  const std::string bad_tag = variant("tag.flo", tag);
  expectErrorNaming([&] { readMiddleburyFlo(bad_tag); }, {bad_tag, "PIEH", "offset 0"}, "tag");
  const std::string zero_w = variant("zero_w.flo", withInt(4, 0));
  expectErrorNaming([&] { readMiddleburyFlo(zero_w); }, {zero_w, "width 0", "offset 4"}, "width 0");
  const std::string neg_h = variant("neg_h.flo", withInt(8, -3));
  expectErrorNaming([&] { readMiddleburyFlo(neg_h); }, {neg_h, "height -3", "offset 8"}, "negative height");
  const std::string huge = variant("huge.flo", withInt(4, 1 << 21));
  expectErrorNaming([&] { readMiddleburyFlo(huge); }, {huge, "width 2097152"}, "absurd width");
  const std::string cut = variant("cut.flo", std::vector<uint8_t>(good.begin(), good.end() - 5));
  expectErrorNaming([&] { readMiddleburyFlo(cut); }, {cut, "truncated", "needs 112", "has 107", "offset 119"},
                    "truncated data");
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  const std::string trailing = variant("trailing.flo", longer);
  expectErrorNaming([&] { readMiddleburyFlo(trailing); }, {trailing, "trailing"}, "trailing bytes");
}

// Random cuts and flipped header bytes give a flow or a std::runtime_error naming the file.
TEST(MiddleburyFlo, RandomDamageGivesErrorsOrFlow) {
  TempDir dir;
  writeMiddleburyFlo(dir / "good.flo", sample());
  const std::vector<uint8_t> good = readBytes(dir / "good.flo");
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> bytes = good;
    if (trial % 2 == 0) bytes.resize(std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng));
    else bytes[std::uniform_int_distribution<size_t>(0, 11)(rng)] ^= static_cast<uint8_t>(1 + trial % 255);
    readsOrNamesTheFile(dir / "damaged.flo", bytes, [](const std::string& p) { return readMiddleburyFlo(p); });
  }
}

}  // namespace
