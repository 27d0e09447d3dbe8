// IEEE 754 binary16 ("half", numpy's float16) <-> binary32 conversions, as VIPER stores optical
// flow in float16. Portable bit arithmetic (no F16C needed) that the compiler can vectorise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace viper::dataset {

/// float32 -> float16, rounding to nearest with ties to even (IEEE's default, as numpy's
/// `astype(np.float16)` and x86's vcvtps2ph). Magnitudes that round above 65504 (the largest
/// half), i.e. |f| >= 65520, become +-inf; magnitudes of at most 2^-25 become +-0; in between
/// the smallest halves are subnormal (spacing 2^-24). The sign of zero is kept. NaN stays NaN:
/// its sign and the top 10 payload bits are kept and the quiet bit is set. Assumes the default
/// floating-point rounding mode (to nearest), which neither ROS nor numpy change.
inline uint16_t floatToHalf(float f) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const uint32_t a = x & 0x7fffffffu;
  // Every case is computed and one is selected, so that loops of this vectorise.
  // Normal half: rebias the exponent and round away the 13 dropped mantissa bits.
  uint32_t normal = (a - 0x38000000u) >> 13;
  const uint32_t rest = a & 0x1fffu;
  normal += static_cast<uint32_t>(rest > 0x1000u) | (static_cast<uint32_t>(rest == 0x1000u) & normal);
  // Subnormal half: |f| * 2^24 (exact) rounded to an integer by one float addition of 2^23,
  // after which that integer is the low mantissa bits of the sum.
  float abs_f;
  std::memcpy(&abs_f, &a, sizeof abs_f);
  const float scaled = abs_f * 0x1p24f + 0x1p23f;
  uint32_t scaled_bits;
  std::memcpy(&scaled_bits, &scaled, sizeof scaled_bits);
  uint32_t h = a < 0x38800000u ? scaled_bits - 0x4b000000u : normal;
  h = a >= 0x477ff000u ? 0x7c00u : h;  // 65520 and above, and inf
  h = a > 0x7f800000u ? 0x7e00u | ((a >> 13) & 0x3ffu) : h;  // NaN
  return static_cast<uint16_t>(sign | h);
}

/// float16 -> float32; exact (every half is a float). NaN keeps its sign and payload.
inline float halfToFloat(uint16_t h) {
  const uint32_t sign = static_cast<uint32_t>(h & 0x8000u) << 16;
  const uint32_t e = (h >> 10) & 0x1fu;
  const uint32_t m = h & 0x3ffu;
  uint32_t x;
  if (e == 0x1f) {
    x = sign | 0x7f800000u | (m << 13);
  } else if (e != 0) {
    x = sign | ((e + 112u) << 23) | (m << 13);
  } else {
    const float sub = static_cast<float>(m) * 0x1p-24f;  // subnormal or zero, exact
    std::memcpy(&x, &sub, sizeof x);
    x |= sign;
  }
  float f;
  std::memcpy(&f, &x, sizeof f);
  return f;
}

/// Converts n floats to halves (see floatToHalf). Returns how many finite inputs overflowed to
/// +-inf (and so became invalid flow in VIPER's convention).
size_t floatsToHalves(const float* in, size_t n, uint16_t* out);

/// Splits n interleaved pairs (u0 v0 u1 v1 ..., a 32FC2 flow image) into halves u[i], v[i] (see
/// floatToHalf; the same bits). Uses x86's F16C where the CPU has it. Returns how many finite
/// inputs overflowed to +-inf.
size_t pairsToHalves(const float* uv, size_t n, uint16_t* u, uint16_t* v);

/// Converts n halves to floats (see halfToFloat).
void halvesToFloats(const uint16_t* in, size_t n, float* out);

}  // namespace viper::dataset
