#include "viper/dataset/float16.h"

#include <cmath>
#include <initializer_list>

#if defined(__x86_64__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace viper::dataset {

namespace {

// Whether a finite float became an infinite half (overflow, invalid flow in VIPER's convention).
inline size_t overflowedTo(float f, uint16_t h) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  return ((h & 0x7fffu) == 0x7c00u) & ((x & 0x7f800000u) != 0x7f800000u);
}

size_t pairsToHalvesPortable(const float* uv, size_t n, uint16_t* u, uint16_t* v, size_t from) {
  size_t overflowed = 0;
  for (size_t i = from; i < n; ++i) {
    u[i] = floatToHalf(uv[2 * i]);
    v[i] = floatToHalf(uv[2 * i + 1]);
    overflowed += overflowedTo(uv[2 * i], u[i]) + overflowedTo(uv[2 * i + 1], v[i]);
  }
  return overflowed;
}

#if defined(__x86_64__)
// 8 pixels at a time: the pairs split by a permutation, each half converted by vcvtps2ph (round to
// nearest even, NaN quieted with its top payload bits: floatToHalf's rules, test_float16).
// Overflow: finite inputs of magnitude >= 65520, which round to inf.
__attribute__((target("avx2,f16c"))) size_t pairsToHalvesF16c(const float* uv, size_t n, uint16_t* u, uint16_t* v) {
  const __m256i split = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 big = _mm256_set1_ps(65520.0f), inf = _mm256_set1_ps(INFINITY);
  size_t overflowed = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 a = _mm256_permutevar8x32_ps(_mm256_loadu_ps(uv + 2 * i), split);      // u0..u3 v0..v3
    const __m256 b = _mm256_permutevar8x32_ps(_mm256_loadu_ps(uv + 2 * i + 8), split);  // u4..u7 v4..v7
    const __m256 us = _mm256_permute2f128_ps(a, b, 0x20), vs = _mm256_permute2f128_ps(a, b, 0x31);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(u + i), _mm256_cvtps_ph(us, _MM_FROUND_TO_NEAREST_INT));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(v + i), _mm256_cvtps_ph(vs, _MM_FROUND_TO_NEAREST_INT));
    for (const __m256 x : {us, vs}) {
      const __m256 m = _mm256_and_ps(x, abs_mask);
      const __m256 over = _mm256_and_ps(_mm256_cmp_ps(m, big, _CMP_GE_OQ), _mm256_cmp_ps(m, inf, _CMP_LT_OQ));
      overflowed += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(over))));
    }
  }
  return overflowed + pairsToHalvesPortable(uv, n, u, v, i);
}
#endif

}  // namespace

size_t pairsToHalves(const float* uv, size_t n, uint16_t* u, uint16_t* v) {
#if defined(__x86_64__)
  // F16C is CPUID leaf 1, ECX bit 29 (clang's __builtin_cpu_supports does not know "f16c").
  static const bool f16c = [] {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    return __builtin_cpu_supports("avx2") && __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & (1u << 29)) != 0;
  }();
  if (f16c) return pairsToHalvesF16c(uv, n, u, v);
#endif
  return pairsToHalvesPortable(uv, n, u, v, 0);
}

size_t floatsToHalves(const float* in, size_t n, uint16_t* out) {
  size_t overflowed = 0;
  for (size_t i = 0; i < n; ++i) {
    out[i] = floatToHalf(in[i]);
    overflowed += overflowedTo(in[i], out[i]);
  }
  return overflowed;
}

void halvesToFloats(const uint16_t* in, size_t n, float* out) {
  for (size_t i = 0; i < n; ++i) out[i] = halfToFloat(in[i]);
}

}  // namespace viper::dataset
