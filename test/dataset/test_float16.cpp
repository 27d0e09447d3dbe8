// float16 conversions against values worked out by hand from IEEE 754 binary16 (1 sign bit, 5
// exponent bits with bias 15, 10 mantissa bits), and against a slow nearest-value search.
#include "viper/dataset/float16.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace {

using viper::dataset::floatToHalf;
using viper::dataset::halfToFloat;

float fromBits(uint32_t x) {
  float f;
  std::memcpy(&f, &x, sizeof f);
  return f;
}
uint32_t bitsOf(float f) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  return x;
}

struct Case {
  float in;
  uint16_t half;
  const char* why;
};

TEST(Float16, HandComputedTable) {
  const Case cases[] = {
      {0.0f, 0x0000, "zero"},
      {-0.0f, 0x8000, "negative zero keeps its sign"},
      {1.0f, 0x3c00, "exponent 15, mantissa 0"},
      {-2.0f, 0xc000, "sign, exponent 16"},
      {0.5f, 0x3800, "exponent 14"},
      {-1.5f, 0xbe00, "mantissa 0x200"},
      {0.1f, 0x2e66, "0.0999755859375 is the nearest half"},
      {3.14159265f, 0x4248, "pi -> 3.140625"},
      {1.0f + 0x1p-11f, 0x3c00, "tie between 0x3c00 and 0x3c01 goes to the even 0x3c00"},
      {1.0f + 3 * 0x1p-11f, 0x3c02, "tie between 0x3c01 and 0x3c02 goes to the even 0x3c02"},
      {1.0f + 0x1p-11f + 0x1p-23f, 0x3c01, "just above the tie rounds up"},
      {1024.5f, 0x6400, "spacing 1 at 1024: tie to even 1024"},
      {1025.5f, 0x6402, "tie to even 1026"},
      {65504.0f, 0x7bff, "largest half"},
      {65519.996f, 0x7bff, "just below the midpoint to 65536 stays finite"},
      {65520.0f, 0x7c00, "midpoint 65520 ties to the even 65536 = inf"},
      {-65520.0f, 0xfc00, "negative overflow to -inf"},
      {1e6f, 0x7c00, "far beyond the range"},
      {std::numeric_limits<float>::infinity(), 0x7c00, "inf"},
      {-std::numeric_limits<float>::infinity(), 0xfc00, "-inf"},
      {0x1p-14f, 0x0400, "smallest normal half"},
      {0x1p-24f, 0x0001, "smallest subnormal half"},
      {0x1p-25f, 0x0000, "half of the smallest subnormal ties to even 0"},
      {0x1p-25f * 1.0000001f, 0x0001, "just above that rounds up"},
      {3 * 0x1p-25f, 0x0002, "1.5 subnormal units tie to even 2"},
      {0x1p-14f - 0x1p-25f, 0x0400, "1023.5 units tie to even 1024 = smallest normal"},
      {-5 * 0x1p-24f, 0x8005, "negative subnormal"},
      {0x1p-26f, 0x0000, "underflow to zero"},
      {1e-40f, 0x0000, "float subnormal underflows"},
      {-1e-40f, 0x8000, "keeping its sign"},
      {fromBits(0x7fc00000u), 0x7e00, "quiet NaN"},
      {fromBits(0xffc00000u), 0xfe00, "negative quiet NaN"},
      {fromBits(0x7fc02000u), 0x7e01, "NaN payload: its top 10 bits are kept"},
      {fromBits(0x7f800001u), 0x7e00, "signalling NaN is quieted"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(floatToHalf(c.in), c.half) << c.why << ": in " << c.in << " (0x" << std::hex << bitsOf(c.in) << ")";
  }
}

TEST(Float16, HalfToFloatTable) {
  EXPECT_EQ(halfToFloat(0x3c00), 1.0f);
  EXPECT_EQ(halfToFloat(0xc000), -2.0f);
  EXPECT_EQ(halfToFloat(0x2e66), 0.0999755859375f);
  EXPECT_EQ(halfToFloat(0x0001), 0x1p-24f);
  EXPECT_EQ(halfToFloat(0x03ff), 1023 * 0x1p-24f);
  EXPECT_EQ(halfToFloat(0x0400), 0x1p-14f);
  EXPECT_EQ(halfToFloat(0x7bff), 65504.0f);
  EXPECT_EQ(halfToFloat(0x7c00), std::numeric_limits<float>::infinity());
  EXPECT_EQ(halfToFloat(0xfc00), -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(halfToFloat(0x7e00)));
  EXPECT_EQ(bitsOf(halfToFloat(0x7e01)), 0x7fc02000u);
  EXPECT_EQ(bitsOf(halfToFloat(0x8000)), 0x80000000u);
}

TEST(Float16, EveryHalfSurvivesARoundTrip) {
  for (uint32_t h = 0; h <= 0xffff; ++h) {
    const float f = halfToFloat(static_cast<uint16_t>(h));
    const uint16_t back = floatToHalf(f);
    if (std::isnan(f)) {
      // NaN comes back NaN, with its sign, quieted.
      EXPECT_EQ(back & 0x7c00u, 0x7c00u);
      EXPECT_NE(back & 0x3ffu, 0u);
      EXPECT_EQ(back & 0x8000u, h & 0x8000u);
      EXPECT_EQ(back, h | 0x200u);
    } else {
      ASSERT_EQ(back, h) << "half 0x" << std::hex << h;
    }
  }
}

// The nearest half by search over the ordered finite halves, ties to the even one: slow, but
// obviously correct given halfToFloat (checked by the table above).
uint16_t nearestHalf(float f) {
  const double a = std::fabs(static_cast<double>(f));
  const uint16_t sign = std::signbit(f) ? 0x8000 : 0;
  if (a >= 65520.0) return sign | 0x7c00;
  uint32_t lo = 0, hi = 0x7bff;  // largest finite
  while (lo < hi) {               // largest h with value(h) <= a
    const uint32_t mid = (lo + hi + 1) / 2;
    if (halfToFloat(static_cast<uint16_t>(mid)) <= a) lo = mid;
    else hi = mid - 1;
  }
  if (lo == 0x7bff) return sign | (a - 65504.0 < 65536.0 - a ? 0x7bff : 0x7c00);
  const double below = halfToFloat(static_cast<uint16_t>(lo)), above = halfToFloat(static_cast<uint16_t>(lo + 1));
  uint32_t pick = lo;
  if (a - below > above - a || (a - below == above - a && (lo & 1))) pick = lo + 1;
  return static_cast<uint16_t>(sign | pick);
}

TEST(Float16, MatchesNearestValueSearch) {
  // Every 251st bit pattern of the finite floats, both signs: ~17 million values.
  size_t checked = 0;
  for (uint64_t x = 0; x < 0x7f800000u; x += 251) {
    for (uint32_t sign : {0u, 0x80000000u}) {
      const float f = fromBits(static_cast<uint32_t>(x) | sign);
      const uint16_t expected = nearestHalf(f);
      if (floatToHalf(f) != expected) {
        FAIL() << "0x" << std::hex << (static_cast<uint32_t>(x) | sign) << " (" << f << "): got 0x" << floatToHalf(f)
               << ", nearest is 0x" << expected;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 16000000u);
}

TEST(Float16, ArrayConversionCountsOverflow) {
  const float in[] = {1.0f, 70000.0f, -1e30f, std::numeric_limits<float>::infinity(), std::nanf(""), 65504.0f};
  uint16_t out[6];
  EXPECT_EQ(viper::dataset::floatsToHalves(in, 6, out), 2u);  // the inf and NaN inputs were not finite
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(out[i], floatToHalf(in[i]));
  float back[6];
  viper::dataset::halvesToFloats(out, 6, back);
  EXPECT_EQ(back[0], 1.0f);
  EXPECT_EQ(back[1], std::numeric_limits<float>::infinity());
  EXPECT_EQ(back[2], -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(back[4]));
  EXPECT_EQ(back[5], 65504.0f);
}

// The flow writer's conversion (F16C on this machine's CPU) gives floatToHalf's bits for every kind
// of value, split from 32FC2 pairs, with the same overflow count.
TEST(Float16, PairsToHalvesMatchesFloatToHalf) {
  std::vector<float> uv;
  for (float f : {0.0f, -0.0f, 1.0f, -2.5f, 65504.0f, 65519.99f, 65520.0f, -70000.0f, 1e-8f, -3e-5f, 5.96e-8f, 2.98e-8f,
                  std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), std::nanf(""),
                  fromBits(0xffc01234u), fromBits(0x7f801fffu), fromBits(0x387fe000u), fromBits(0x33000000u)})
    uv.push_back(f);
  uint32_t state = 12345;
  while (uv.size() < 2 * 1003) {  // random bit patterns; an odd count of pixels leaves a tail
    state = state * 1664525u + 1013904223u;
    uv.push_back(fromBits(state));
  }
  const size_t n = uv.size() / 2;
  std::vector<uint16_t> u(n), v(n);
  const size_t overflowed = viper::dataset::pairsToHalves(uv.data(), n, u.data(), v.data());
  size_t expected_overflow = 0;
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(u[i], floatToHalf(uv[2 * i])) << "u " << i << " 0x" << std::hex << bitsOf(uv[2 * i]);
    ASSERT_EQ(v[i], floatToHalf(uv[2 * i + 1])) << "v " << i << " 0x" << std::hex << bitsOf(uv[2 * i + 1]);
    uint16_t h;
    expected_overflow += viper::dataset::floatsToHalves(&uv[2 * i], 1, &h) + viper::dataset::floatsToHalves(&uv[2 * i + 1], 1, &h);
  }
  EXPECT_EQ(overflowed, expected_overflow);
  EXPECT_GT(expected_overflow, 100u) << "random bits overflow often: the count is exercised";
}

}  // namespace
