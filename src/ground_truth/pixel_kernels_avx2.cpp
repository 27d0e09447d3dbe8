// The AVX2 kernels of pixel_kernels.h: class pictures 32 pixels a step, depth conversions 8.
#include "pixel_kernels.h"

#ifdef VIPER_X86
#include <immintrin.h>

#ifdef __clang__
#pragma clang fp contract(off)
#endif

#include <cstdint>
#include <limits>

namespace viper {
namespace pixel_kernels {
namespace {

#define VIPER_AVX2 __attribute__((target("avx2,fma,popcnt"))) VIPER_NO_FP_CONTRACT
#define VIPER_AVX2_INLINE __attribute__((target("avx2,fma,popcnt"), always_inline)) VIPER_NO_FP_CONTRACT inline

// Per 16-byte lane: 4 pixels of 3 bytes spread to 4 bytes each (the fourth 0), and back.
VIPER_AVX2_INLINE __m256i spreadRgb() {
  return _mm256_setr_epi8(0, 1, 2, -1, 3, 4, 5, -1, 6, 7, 8, -1, 9, 10, 11, -1, 0, 1, 2, -1, 3, 4, 5, -1, 6, 7, 8, -1,
                          9, 10, 11, -1);
}
VIPER_AVX2_INLINE __m256i packRgb() {
  return _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13,
                          14, -1, -1, -1, -1);
}

// Four vectors of 8 pixels of 4 bytes (rgb and a byte that is dropped), packed with packRgb per
// lane (dwords 0-2 and 4-6 hold the pixels), to 96 bytes of rgb at `out`.
VIPER_AVX2_INLINE __m256i dwords(__m256i v, int a, int b, int c, int d, int e, int f, int g, int h) {
  return _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(a, b, c, d, e, f, g, h));
}
// 32 bytes of a class picture, with non-temporal stores where `at` is 16-byte aligned (every block of
// a malloc'd picture): nothing here reads the 6 MB a 1080p picture again, and they spare reading
// them into the cache before writing (the instances node, when it still made its pictures here:
// 11.5-11.8 -> 10.7-11.3 ms a frame in measure_pipeline.sh on the AVX2-only VM, alternated; it now
// makes them from its runs of draws and calls only the overlay). Each kernel ends with a store fence.
VIPER_AVX2_INLINE void store32(__m256i* at, __m256i v) {
  if ((reinterpret_cast<uintptr_t>(at) & 15) == 0) {
    _mm_stream_si128(reinterpret_cast<__m128i*>(at), _mm256_castsi256_si128(v));
    _mm_stream_si128(reinterpret_cast<__m128i*>(at) + 1, _mm256_extracti128_si256(v, 1));
  } else {
    _mm256_storeu_si256(at, v);
  }
}
VIPER_AVX2_INLINE void storeRgb32(const __m256i q[4], uint8_t* out) {
  auto* o = reinterpret_cast<__m256i*>(out);
  store32(o, _mm256_blend_epi32(dwords(q[0], 0, 1, 2, 4, 5, 6, 0, 0), dwords(q[1], 0, 0, 0, 0, 0, 0, 0, 1), 0xc0));
  store32(o + 1,
          _mm256_blend_epi32(dwords(q[1], 2, 4, 5, 6, 0, 0, 0, 0), dwords(q[2], 0, 0, 0, 0, 0, 1, 2, 4), 0xf0));
  store32(o + 2,
          _mm256_blend_epi32(dwords(q[2], 5, 6, 0, 0, 0, 0, 0, 0), dwords(q[3], 0, 0, 0, 1, 2, 4, 5, 6), 0xfc));
}

// The 8 class ids at `ids` as dwords.
VIPER_AVX2_INLINE __m256i ids8(const uint8_t* ids) {
  return _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(ids)));
}

// The blend of semantic_overlay.cpp per byte: (c (256 - w) + p w + 128) >> 8, in 16-bit lanes (the
// sum is at most 255 * 256 + 128, so it does not wrap), even and odd bytes apart.
VIPER_AVX2_INLINE __m256i blendBytes(__m256i c, __m256i p, __m256i wc, __m256i wp) {
  const __m256i low = _mm256_set1_epi16(0x00ff), round = _mm256_set1_epi16(128);
  const __m256i even = _mm256_add_epi16(_mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(c, low), wc),
                                                         _mm256_mullo_epi16(_mm256_and_si256(p, low), wp)),
                                        round);
  const __m256i odd = _mm256_add_epi16(_mm256_add_epi16(_mm256_mullo_epi16(_mm256_srli_epi16(c, 8), wc),
                                                        _mm256_mullo_epi16(_mm256_srli_epi16(p, 8), wp)),
                                       round);
  return _mm256_or_si256(_mm256_srli_epi16(even, 8), _mm256_andnot_si256(low, odd));
}

}  // namespace

// 32 pixels a step: per pixel the dword class | (id & 0xff00) | (id & 0xff) << 16, that is r = class,
// g = id / 256, b = id % 256 of the id's low 16 bits, packed to 3 bytes.
VIPER_AVX2 size_t encodeViperAvx2(const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb) {
  const __m256i pack = packRgb(), high = _mm256_set1_epi32(0xff00), low = _mm256_set1_epi32(0xff);
  size_t i = 0;
  for (; i + 32 <= n; i += 32) {
    __m256i q[4];
    for (int g = 0; g < 4; ++g) {
      const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(instance_ids + i + 8 * g));
      const __m256i word = _mm256_or_si256(_mm256_or_si256(ids8(class_ids + i + 8 * g), _mm256_and_si256(id, high)),
                                           _mm256_slli_epi32(_mm256_and_si256(id, low), 16));
      q[g] = _mm256_shuffle_epi8(word, pack);
    }
    storeRgb32(q, rgb + 3 * i);
  }
  _mm_sfence();
  return i;
}

VIPER_AVX2 size_t colorizeAvx2(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb) {
  const __m256i pack = packRgb();
  const int* table = reinterpret_cast<const int*>(palette);
  size_t i = 0;
  for (; i + 32 <= n; i += 32) {
    __m256i q[4];
    for (int g = 0; g < 4; ++g)
      q[g] = _mm256_shuffle_epi8(_mm256_i32gather_epi32(table, ids8(ids + i + 8 * g), 4), pack);
    storeRgb32(q, rgb + 3 * i);
  }
  _mm_sfence();
  return i;
}

VIPER_AVX2 size_t overlayAvx2(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette, int weight,
                              uint8_t* rgb) {
  const __m256i spread = spreadRgb(), pack = packRgb(), zero = _mm256_setzero_si256();
  const __m256i wc = _mm256_set1_epi16(static_cast<int16_t>(256 - weight)),
                wp = _mm256_set1_epi16(static_cast<int16_t>(weight));
  // The 24 bytes of 8 pixels' camera colors, 3 dwords to a lane, from 32 bytes at 24 g (the last
  // group from 64, so as not to read past the 96 bytes).
  const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 2, 3, 4, 5, 5);
  const __m256i lanes_last = _mm256_add_epi32(lanes, _mm256_set1_epi32(2));
  const int* table = reinterpret_cast<const int*>(palette);
  size_t i = 0;
  for (; i + 32 <= n; i += 32) {
    const uint8_t* in = color + 3 * i;
    __m256i q[4];
    for (int g = 0; g < 4; ++g) {
      const __m256i raw = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + (g < 3 ? 24 * g : 64)));
      const __m256i c = _mm256_shuffle_epi8(_mm256_permutevar8x32_epi32(raw, g < 3 ? lanes : lanes_last), spread);
      const __m256i id = ids8(ids + i + 8 * g);
      // Class 0 keeps the camera color: its lanes blend the camera color with itself.
      const __m256i p = _mm256_mask_i32gather_epi32(c, table, id, _mm256_cmpgt_epi32(id, zero), 4);
      q[g] = _mm256_shuffle_epi8(blendBytes(c, p, wc, wp), pack);
    }
    storeRgb32(q, rgb + 3 * i);
  }
  _mm_sfence();
  return i;
}

namespace {

// Rows 2 and 3 of the projections of 8 pixels, lanes 0-3 in [0] and 4-7 in [1].
struct Rows8 {
  __m256d p22[2], p23[2], p32[2], p33[2];
};

VIPER_AVX2_INLINE Rows8 rowsOf(const DepthRows& rows, uint32_t s) {
  const __m256d p22 = _mm256_set1_pd(rows.p22[s]), p23 = _mm256_set1_pd(rows.p23[s]), p32 = _mm256_set1_pd(rows.p32[s]),
                p33 = _mm256_set1_pd(rows.p33[s]);
  return {{p22, p22}, {p23, p23}, {p32, p32}, {p33, p33}};
}

// Whether the 8 draw ids at `ids` are all `slot` (a slot, so below rows.size).
VIPER_AVX2_INLINE bool all8(const uint32_t* ids, uint32_t slot) {
  const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids));
  return _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(id, _mm256_set1_epi32(static_cast<int>(slot))))) ==
         0xff;
}

// The groups of lanes of 8 pixels that share a slot (bit masks).
struct Groups8 {
  uint32_t slot[8];
  int lanes[8];
  int count = 0;
};

// The slots of 8 draw ids (ids >= rows.size: slot 0), their groups and rows.
VIPER_AVX2_INLINE Rows8 rowsOf(const uint32_t* ids, const DepthRows& rows, Groups8& groups) {
  __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids));
  const __m256i last = _mm256_set1_epi32(static_cast<int>(rows.size - 1));
  id = _mm256_and_si256(id, _mm256_cmpeq_epi32(_mm256_min_epu32(id, last), id));  // id <= size - 1
  alignas(32) uint32_t lane[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lane), id);
  Rows8 r = rowsOf(rows, lane[0]);
  for (int left = 0xff; left;) {
    const uint32_t s = lane[__builtin_ctz(left)];
    const __m256i m32 = _mm256_cmpeq_epi32(id, _mm256_set1_epi32(static_cast<int>(s)));
    const int m = _mm256_movemask_ps(_mm256_castsi256_ps(m32));
    groups.slot[groups.count] = s, groups.lanes[groups.count] = m, ++groups.count;
    left &= ~m;
    if (groups.count == 1) continue;
    for (int h = 0; h < 2; ++h) {
      const __m256d mh = _mm256_castsi256_pd(
          _mm256_cvtepi32_epi64(h == 0 ? _mm256_castsi256_si128(m32) : _mm256_extracti128_si256(m32, 1)));
      r.p22[h] = _mm256_blendv_pd(r.p22[h], _mm256_set1_pd(rows.p22[s]), mh);
      r.p23[h] = _mm256_blendv_pd(r.p23[h], _mm256_set1_pd(rows.p23[s]), mh);
      r.p32[h] = _mm256_blendv_pd(r.p32[h], _mm256_set1_pd(rows.p32[s]), mh);
      r.p33[h] = _mm256_blendv_pd(r.p33[h], _mm256_set1_pd(rows.p33[s]), mh);
    }
  }
  return r;
}

// The low halves of 4 double lanes' masks as 4 float lanes' masks.
VIPER_AVX2_INLINE __m128 floatLanes(__m256d mask) {
  return _mm256_castps256_ps128(
      _mm256_permutevar8x32_ps(_mm256_castpd_ps(mask), _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
}

// As DepthLinearizer::toMetres for 8 pixels: d in [0, 1), z_ndc = 2 d - 1,
// (P23 - z_ndc P33) / (P22 - z_ndc P32) in double, rounded to float, positive and finite (a zero
// denominator gives an infinity or NaN), else NaN. The checks are made on the 8 floats at once.
VIPER_AVX2_INLINE void metres8(const Rows8& r, const float* window, float* metres) {
  const __m256d one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0);
  const __m256 w = _mm256_loadu_ps(window);
  __m128 half[2];
  for (int h = 0; h < 2; ++h) {
    const __m256d d = _mm256_cvtps_pd(h == 0 ? _mm256_castps256_ps128(w) : _mm256_extractf128_ps(w, 1));
    const __m256d z_ndc = _mm256_sub_pd(_mm256_mul_pd(two, d), one);
    const __m256d denom = _mm256_sub_pd(r.p22[h], _mm256_mul_pd(z_ndc, r.p32[h]));
    half[h] = _mm256_cvtpd_ps(_mm256_div_pd(_mm256_sub_pd(r.p23[h], _mm256_mul_pd(z_ndc, r.p33[h])), denom));
  }
  const __m256 depth = _mm256_insertf128_ps(_mm256_castps128_ps256(half[0]), half[1], 1);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 ok = _mm256_and_ps(
      _mm256_and_ps(_mm256_cmp_ps(w, zero, _CMP_GE_OQ), _mm256_cmp_ps(w, _mm256_set1_ps(1.0f), _CMP_LT_OQ)),
      _mm256_and_ps(_mm256_cmp_ps(depth, zero, _CMP_GT_OQ),
                    _mm256_cmp_ps(depth, _mm256_set1_ps(std::numeric_limits<float>::infinity()), _CMP_LT_OQ)));
  _mm256_storeu_ps(metres, _mm256_blendv_ps(_mm256_set1_ps(std::numeric_limits<float>::quiet_NaN()), depth, ok));
}

// As windowDepthFromMetres for 8 pixels: m positive and finite, z = -m,
// d = 0.5 ((P22 z + P23) / (P32 z + P33) + 1) in [0, 1), else 1. Returns the lanes with depth.
VIPER_AVX2_INLINE int window8(const Rows8& r, const float* metres, float* window) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5),
                inf = _mm256_set1_pd(std::numeric_limits<double>::infinity()), sign = _mm256_set1_pd(-0.0);
  int with_depth = 0;
  for (int h = 0; h < 2; ++h) {
    const __m256d m = _mm256_cvtps_pd(_mm_loadu_ps(metres + 4 * h));
    const __m256d z = _mm256_xor_pd(m, sign);
    const __m256d z_ndc = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(r.p22[h], z), r.p23[h]),
                                        _mm256_add_pd(_mm256_mul_pd(r.p32[h], z), r.p33[h]));
    const __m256d d = _mm256_mul_pd(half, _mm256_add_pd(z_ndc, one));
    const __m256d ok =
        _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(m, zero, _CMP_GT_OQ), _mm256_cmp_pd(m, inf, _CMP_LT_OQ)),
                      _mm256_and_pd(_mm256_cmp_pd(d, zero, _CMP_GE_OQ), _mm256_cmp_pd(d, one, _CMP_LT_OQ)));
    _mm_storeu_ps(window + 4 * h, _mm_blendv_ps(_mm_set1_ps(1.0f), _mm256_cvtpd_ps(d), floatLanes(ok)));
    with_depth |= _mm256_movemask_pd(ok) << (4 * h);
  }
  return with_depth;
}

}  // namespace

// Blocks of 8 pixels of the slot of the block before (nearly all: draws cover runs of pixels) reuse
// its rows. kMask: in the same pass over the ids, their largest and the primitive ids masked.
template <bool kMask>
VIPER_AVX2_INLINE size_t metresBlocks(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                      float* metres, int32_t* primitives, uint32_t* largest) {
  size_t i = 0;
  uint32_t slot = 0;
  Rows8 r = rowsOf(rows, slot);
  const __m256i zero = _mm256_setzero_si256();
  __m256i top = zero;
  for (; i + 8 <= n; i += 8) {
    if (kMask) {
      const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + i));
      top = _mm256_max_epu32(top, id);
      auto* p = reinterpret_cast<__m256i*>(primitives + i);
      _mm256_storeu_si256(p, _mm256_or_si256(_mm256_loadu_si256(p), _mm256_cmpeq_epi32(id, zero)));
    }
    if (!ids || all8(ids + i, slot)) {
      metres8(r, window + i, metres + i);
    } else {
      Groups8 g;
      const Rows8 mixed = rowsOf(ids + i, rows, g);
      metres8(mixed, window + i, metres + i);
      if (g.count == 1) slot = g.slot[0], r = mixed;
    }
  }
  if (kMask) {
    alignas(32) uint32_t lanes[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), top);
    *largest = 0;
    for (uint32_t v : lanes) *largest = v > *largest ? v : *largest;
  }
  return i;
}

VIPER_AVX2 size_t depthMetresAvx2(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                  float* metres) {
  return metresBlocks<false>(ids, window, n, rows, metres, nullptr, nullptr);
}

VIPER_AVX2 size_t depthMetresMaskingAvx2(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                         float* metres, int32_t* primitives, uint32_t& largest) {
  return metresBlocks<true>(ids, window, n, rows, metres, primitives, &largest);
}

VIPER_AVX2 size_t windowDepthAvx2(const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows,
                                  float* window, uint32_t* good, uint32_t* bad) {
  SlotCounts counter{good, bad};
  size_t i = 0;
  uint32_t slot = 0;
  Rows8 r = rowsOf(rows, slot);
  for (; i + 8 <= n; i += 8) {
    if (all8(ids + i, slot)) {
      counter.add(slot, 0xff, window8(r, metres + i, window + i));
    } else {
      Groups8 g;
      const Rows8 mixed = rowsOf(ids + i, rows, g);
      const int ok = window8(mixed, metres + i, window + i);
      for (int k = 0; k < g.count; ++k) counter.add(g.slot[k], g.lanes[k], ok);
      if (g.count == 1) slot = g.slot[0], r = mixed;
    }
  }
  counter.flush();
  return i;
}

}  // namespace pixel_kernels
}  // namespace viper

#endif
