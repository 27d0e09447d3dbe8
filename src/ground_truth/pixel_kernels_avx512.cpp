// The AVX-512 kernels of pixel_kernels.h: class pictures 64 pixels a step, depth conversions 8.
#include "pixel_kernels.h"

#ifdef VIPER_X86
#include <immintrin.h>

#ifdef __clang__
#pragma clang fp contract(off)
#endif
// GCC 12's AVX-512 intrinsics initialise their undefined operands from themselves, which
// -Wmaybe-uninitialized and -Wuninitialized report at every use (GCC bug 105593, fixed in GCC 13).
#ifndef __clang__
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

#include <limits>

namespace viper {
namespace pixel_kernels {
namespace {

#define VIPER_AVX512 __attribute__((target("avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt"))) VIPER_NO_FP_CONTRACT
#define VIPER_AVX512_INLINE                                                                    \
  __attribute__((target("avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt"), always_inline)) \
  VIPER_NO_FP_CONTRACT inline

// Per 16-byte lane: 4 pixels of 3 bytes spread to 4 bytes each (the fourth 0), and back.
VIPER_AVX512_INLINE __m512i spreadRgb() {
  return _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 2, -1, 3, 4, 5, -1, 6, 7, 8, -1, 9, 10, 11, -1));
}
VIPER_AVX512_INLINE __m512i packRgb() {
  return _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1));
}

// Four vectors of 16 pixels of 4 bytes (rgb and a byte that is dropped), packed with packRgb per
// lane (3 dwords of each lane hold 4 pixels), to 192 bytes of rgb at `out`.
VIPER_AVX512_INLINE void storeRgb64(const __m512i q[4], uint8_t* out) {
  const __m512i i0 = _mm512_setr_epi32(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 16, 17, 18, 20);
  const __m512i i1 = _mm512_setr_epi32(5, 6, 8, 9, 10, 12, 13, 14, 16, 17, 18, 20, 21, 22, 24, 25);
  const __m512i i2 = _mm512_setr_epi32(10, 12, 13, 14, 16, 17, 18, 20, 21, 22, 24, 25, 26, 28, 29, 30);
  _mm512_storeu_si512(out, _mm512_permutex2var_epi32(q[0], i0, q[1]));
  _mm512_storeu_si512(out + 64, _mm512_permutex2var_epi32(q[1], i1, q[2]));
  _mm512_storeu_si512(out + 128, _mm512_permutex2var_epi32(q[2], i2, q[3]));
}

// The 16 class ids at `ids` as dwords.
VIPER_AVX512_INLINE __m512i ids16(const uint8_t* ids) {
  return _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(ids)));
}

// The blend of semantic_overlay.cpp per byte: (c (256 - w) + p w + 128) >> 8, in 16-bit lanes (the
// sum is at most 255 * 256 + 128, so it does not wrap), even and odd bytes apart.
VIPER_AVX512_INLINE __m512i blendBytes(__m512i c, __m512i p, __m512i wc, __m512i wp) {
  const __m512i low = _mm512_set1_epi16(0x00ff), round = _mm512_set1_epi16(128);
  const __m512i even = _mm512_add_epi16(_mm512_add_epi16(_mm512_mullo_epi16(_mm512_and_si512(c, low), wc),
                                                         _mm512_mullo_epi16(_mm512_and_si512(p, low), wp)),
                                        round);
  const __m512i odd = _mm512_add_epi16(_mm512_add_epi16(_mm512_mullo_epi16(_mm512_srli_epi16(c, 8), wc),
                                                        _mm512_mullo_epi16(_mm512_srli_epi16(p, 8), wp)),
                                       round);
  return _mm512_or_si512(_mm512_srli_epi16(even, 8), _mm512_andnot_si512(low, odd));
}

}  // namespace

VIPER_AVX512 size_t colorizeAvx512(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb) {
  const __m512i pack = packRgb();
  size_t i = 0;
  for (; i + 64 <= n; i += 64) {
    __m512i q[4];
    for (int g = 0; g < 4; ++g)
      q[g] = _mm512_shuffle_epi8(_mm512_i32gather_epi32(ids16(ids + i + 16 * g), palette, 4), pack);
    storeRgb64(q, rgb + 3 * i);
  }
  return i;
}

VIPER_AVX512 size_t overlayAvx512(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette,
                                  int weight, uint8_t* rgb) {
  const __m512i spread = spreadRgb(), pack = packRgb();
  const __m512i wc = _mm512_set1_epi16(static_cast<int16_t>(256 - weight)),
                wp = _mm512_set1_epi16(static_cast<int16_t>(weight));
  // Dwords 12 g .. 12 g + 11 of the 48 of 64 pixels' camera colors, 3 to a lane: group 0 from the
  // first vector, 1 from the first two, 2 from the last two, 3 from the last.
  const __m512i c0 = _mm512_setr_epi32(0, 1, 2, 2, 3, 4, 5, 5, 6, 7, 8, 8, 9, 10, 11, 11);
  const __m512i c1 = _mm512_add_epi32(c0, _mm512_set1_epi32(12));
  const __m512i c2 = _mm512_add_epi32(c0, _mm512_set1_epi32(8));
  const __m512i c3 = _mm512_add_epi32(c0, _mm512_set1_epi32(4));
  size_t i = 0;
  for (; i + 64 <= n; i += 64) {
    const uint8_t* in = color + 3 * i;
    const __m512i v0 = _mm512_loadu_si512(in), v1 = _mm512_loadu_si512(in + 64), v2 = _mm512_loadu_si512(in + 128);
    const __m512i cam[4] = {_mm512_permutexvar_epi32(c0, v0), _mm512_permutex2var_epi32(v0, c1, v1),
                            _mm512_permutex2var_epi32(v1, c2, v2), _mm512_permutexvar_epi32(c3, v2)};
    __m512i q[4];
    for (int g = 0; g < 4; ++g) {
      const __m512i c = _mm512_shuffle_epi8(cam[g], spread);
      const __m512i id = ids16(ids + i + 16 * g);
      // Class 0 keeps the camera color: its lanes blend the camera color with itself.
      const __m512i p = _mm512_mask_i32gather_epi32(c, _mm512_test_epi32_mask(id, id), id, palette, 4);
      q[g] = _mm512_shuffle_epi8(blendBytes(c, p, wc, wp), pack);
    }
    storeRgb64(q, rgb + 3 * i);
  }
  return i;
}

namespace {

#define VIPER_VBMI \
  __attribute__((target("avx512vbmi,avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt"))) VIPER_NO_FP_CONTRACT
#define VIPER_VBMI_INLINE                                                                                 \
  __attribute__((target("avx512vbmi,avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt"), always_inline)) \
  VIPER_NO_FP_CONTRACT inline

// A 256-byte table in four vectors, one channel of the palette.
struct ByteTable {
  __m512i q[4];
};

// The 256 entries of channel `ch` of the palette.
VIPER_VBMI_INLINE ByteTable channel(const uint32_t* palette, int ch) {
  alignas(64) uint8_t bytes[256];
  for (int c = 0; c < 256; ++c) bytes[c] = static_cast<uint8_t>(palette[c] >> (8 * ch));
  ByteTable t;
  for (int k = 0; k < 4; ++k) t.q[k] = _mm512_load_si512(bytes + 64 * k);
  return t;
}

// The table's entries for 64 ids: the low 7 bits pick one of 128 bytes, bit 7 which half.
VIPER_VBMI_INLINE __m512i lookup(const ByteTable& t, __m512i ids, __mmask64 high) {
  return _mm512_mask_blend_epi8(high, _mm512_permutex2var_epi8(t.q[0], ids, t.q[1]),
                                _mm512_permutex2var_epi8(t.q[2], ids, t.q[3]));
}

// Byte permutes that interleave 64 pixels' r, g and b (64 bytes each) into 192 bytes of rgb: the
// output vector k takes r and g from two-table permutes (index pixel, + 64 for g) and b where
// `b_lanes` is set (index pixel); `pixel` is each byte's pixel.
struct Interleave {
  __m512i rg[3], pixel[3];
  __mmask64 b_lanes[3];
};

VIPER_VBMI_INLINE Interleave interleave() {
  Interleave v;
  for (int k = 0; k < 3; ++k) {
    alignas(64) uint8_t rg[64], pixel[64];
    uint64_t b = 0;
    for (int t = 0; t < 64; ++t) {
      const int j = 64 * k + t, ch = j % 3;
      pixel[t] = static_cast<uint8_t>(j / 3);
      rg[t] = static_cast<uint8_t>(j / 3 + (ch == 1 ? 64 : 0));
      if (ch == 2) b |= uint64_t{1} << t;
    }
    v.rg[k] = _mm512_load_si512(rg), v.pixel[k] = _mm512_load_si512(pixel), v.b_lanes[k] = b;
  }
  return v;
}

VIPER_VBMI_INLINE __m512i interleaved(const Interleave& v, int k, __m512i r, __m512i g, __m512i b) {
  return _mm512_mask_permutexvar_epi8(_mm512_permutex2var_epi8(r, v.rg[k], g), v.b_lanes[k], v.pixel[k], b);
}

}  // namespace

VIPER_VBMI size_t colorizeAvx512Vbmi(const uint8_t* ids, size_t n, const uint32_t* palette, uint8_t* rgb) {
  const ByteTable tr = channel(palette, 0), tg = channel(palette, 1), tb = channel(palette, 2);
  const Interleave v = interleave();
  size_t i = 0;
  for (; i + 64 <= n; i += 64) {
    const __m512i id = _mm512_loadu_si512(ids + i);
    const __mmask64 high = _mm512_movepi8_mask(id);
    const __m512i r = lookup(tr, id, high), g = lookup(tg, id, high), b = lookup(tb, id, high);
    for (int k = 0; k < 3; ++k) _mm512_storeu_si512(rgb + 3 * i + 64 * k, interleaved(v, k, r, g, b));
  }
  return i;
}

VIPER_VBMI size_t overlayAvx512Vbmi(const uint8_t* color, const uint8_t* ids, size_t n, const uint32_t* palette,
                                    int weight, uint8_t* rgb) {
  const ByteTable tr = channel(palette, 0), tg = channel(palette, 1), tb = channel(palette, 2);
  const Interleave v = interleave();
  const __m512i wc = _mm512_set1_epi16(static_cast<int16_t>(256 - weight)),
                wp = _mm512_set1_epi16(static_cast<int16_t>(weight));
  size_t i = 0;
  for (; i + 64 <= n; i += 64) {
    const __m512i id = _mm512_loadu_si512(ids + i);
    const __mmask64 high = _mm512_movepi8_mask(id);
    const __m512i r = lookup(tr, id, high), g = lookup(tg, id, high), b = lookup(tb, id, high);
    for (int k = 0; k < 3; ++k) {
      const __m512i c = _mm512_loadu_si512(color + 3 * i + 64 * k);
      // Class 0 keeps the camera color: its bytes blend the camera color with itself.
      const __m512i id_k = _mm512_permutexvar_epi8(v.pixel[k], id);
      const __m512i p = _mm512_mask_mov_epi8(interleaved(v, k, r, g, b), _mm512_testn_epi8_mask(id_k, id_k), c);
      _mm512_storeu_si512(rgb + 3 * i + 64 * k, blendBytes(c, p, wc, wp));
    }
  }
  return i;
}

namespace {

// Rows 2 and 3 of the projections of 8 pixels.
struct Rows8 {
  __m512d p22, p23, p32, p33;
};

VIPER_AVX512_INLINE Rows8 rowsOf(const DepthRows& rows, uint32_t s) {
  return {_mm512_set1_pd(rows.p22[s]), _mm512_set1_pd(rows.p23[s]), _mm512_set1_pd(rows.p32[s]),
          _mm512_set1_pd(rows.p33[s])};
}

// 8 pixels' slots (ids >= rows.size: slot 0): whether they are all `first`, the slot of the first.
struct Slots8 {
  __m256i id;
  uint32_t first;
  __mmask8 first_lanes;
};

VIPER_AVX512_INLINE Slots8 slotsOf(const uint32_t* ids, const DepthRows& rows) {
  __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids));
  id = _mm256_maskz_mov_epi32(_mm256_cmplt_epu32_mask(id, _mm256_set1_epi32(static_cast<int>(rows.size))), id);
  const uint32_t first = static_cast<uint32_t>(_mm_cvtsi128_si32(_mm256_castsi256_si128(id)));
  return {id, first, _mm256_cmpeq_epi32_mask(id, _mm256_set1_epi32(static_cast<int>(first)))};
}

// The rows of 8 pixels of several slots (s.first_lanes != 0xff), and the groups of lanes that share
// a slot, first the first lane's.
struct Groups8 {
  uint32_t slot[8];
  __mmask8 lanes[8];
  int count;
};

VIPER_AVX512_INLINE Rows8 mixedRows(const Slots8& s, const DepthRows& rows, Groups8& g) {
  Rows8 r = rowsOf(rows, s.first);
  g.slot[0] = s.first, g.lanes[0] = s.first_lanes, g.count = 1;
  for (__mmask8 left = static_cast<__mmask8>(~s.first_lanes); left;) {
    const __m256i lane = _mm256_permutexvar_epi32(_mm256_set1_epi32(__builtin_ctz(left)), s.id);
    const __mmask8 m = _mm256_cmpeq_epi32_mask(s.id, lane);
    const uint32_t slot = static_cast<uint32_t>(_mm_cvtsi128_si32(_mm256_castsi256_si128(lane)));
    r.p22 = _mm512_mask_mov_pd(r.p22, m, _mm512_set1_pd(rows.p22[slot]));
    r.p23 = _mm512_mask_mov_pd(r.p23, m, _mm512_set1_pd(rows.p23[slot]));
    r.p32 = _mm512_mask_mov_pd(r.p32, m, _mm512_set1_pd(rows.p32[slot]));
    r.p33 = _mm512_mask_mov_pd(r.p33, m, _mm512_set1_pd(rows.p33[slot]));
    g.slot[g.count] = slot, g.lanes[g.count] = m, ++g.count;
    left = static_cast<__mmask8>(left & ~m);
  }
  return r;
}

// As DepthLinearizer::toMetres for 8 pixels: d in [0, 1), z_ndc = 2 d - 1,
// (P23 - z_ndc P33) / (P22 - z_ndc P32) positive and finite (a zero denominator gives an infinity or
// NaN), else NaN.
VIPER_AVX512_INLINE void metres8(const Rows8& r, const float* window, float* metres) {
  const __m512d one = _mm512_set1_pd(1.0);
  const __m256 w = _mm256_loadu_ps(window);
  const __m512d d = _mm512_cvtps_pd(w);
  const __m512d z_ndc = _mm512_sub_pd(_mm512_mul_pd(_mm512_set1_pd(2.0), d), one);
  const __m512d denom = _mm512_sub_pd(r.p22, _mm512_mul_pd(z_ndc, r.p32));
  const __m256 depth = _mm512_cvtpd_ps(_mm512_div_pd(_mm512_sub_pd(r.p23, _mm512_mul_pd(z_ndc, r.p33)), denom));
  // As a float: not NaN, +-0, +-infinity or negative.
  const __mmask8 ok =
      _mm256_cmp_ps_mask(w, _mm256_setzero_ps(), _CMP_GE_OQ) & _mm256_cmp_ps_mask(w, _mm256_set1_ps(1.0f), _CMP_LT_OQ) &
      static_cast<__mmask8>(~_mm256_fpclass_ps_mask(depth, 0x01 | 0x02 | 0x04 | 0x08 | 0x10 | 0x40 | 0x80));
  _mm256_storeu_ps(metres, _mm256_mask_blend_ps(ok, _mm256_set1_ps(std::numeric_limits<float>::quiet_NaN()), depth));
}

// As windowDepthFromMetres for 8 pixels: m positive and finite, z = -m,
// d = 0.5 ((P22 z + P23) / (P32 z + P33) + 1) in [0, 1), else 1. Returns the lanes with depth.
VIPER_AVX512_INLINE __mmask8 window8(const Rows8& r, const float* metres, float* window) {
  const __m512d one = _mm512_set1_pd(1.0);
  const __m256 m = _mm256_loadu_ps(metres);
  const __m512d z = _mm512_xor_pd(_mm512_cvtps_pd(m), _mm512_set1_pd(-0.0));
  const __m512d z_ndc =
      _mm512_div_pd(_mm512_add_pd(_mm512_mul_pd(r.p22, z), r.p23), _mm512_add_pd(_mm512_mul_pd(r.p32, z), r.p33));
  const __m512d d = _mm512_mul_pd(_mm512_set1_pd(0.5), _mm512_add_pd(z_ndc, one));
  const __mmask8 ok = _mm256_cmp_ps_mask(m, _mm256_setzero_ps(), _CMP_GT_OQ) &
                      _mm256_cmp_ps_mask(m, _mm256_set1_ps(std::numeric_limits<float>::infinity()), _CMP_LT_OQ) &
                      _mm512_cmp_pd_mask(d, _mm512_setzero_pd(), _CMP_GE_OQ) & _mm512_cmp_pd_mask(d, one, _CMP_LT_OQ);
  _mm256_storeu_ps(window, _mm256_mask_blend_ps(ok, _mm256_set1_ps(1.0f), _mm512_cvtpd_ps(d)));
  return ok;
}

// Whether the 16 draw ids at `ids` are all `slot` (a slot, so below rows.size).
VIPER_AVX512_INLINE bool all16(const uint32_t* ids, uint32_t slot) {
  return _mm512_cmpneq_epi32_mask(_mm512_loadu_si512(ids), _mm512_set1_epi32(static_cast<int>(slot))) == 0;
}

}  // namespace

// Blocks of 16 pixels of the slot of the block before (nearly all: draws cover runs of pixels)
// reuse its rows; the others go in two blocks of 8, each of one slot or of several. kMask: in the
// same pass over the ids (not null), their largest and the primitive ids masked.
template <bool kMask>
VIPER_AVX512_INLINE size_t metresBlocks(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                        float* metres, int32_t* primitives, uint32_t* largest) {
  size_t i = 0;
  uint32_t slot = 0;
  Rows8 r = rowsOf(rows, slot);
  if (!ids) {
    for (; i + 8 <= n; i += 8) metres8(r, window + i, metres + i);
    return i;
  }
  __m512i top = _mm512_setzero_si512();
  for (; i + 16 <= n; i += 16) {
    if (kMask) {
      const __m512i id = _mm512_loadu_si512(ids + i);
      top = _mm512_max_epu32(top, id);
      // Only the pixels no draw covers are written.
      _mm512_mask_storeu_epi32(primitives + i, _mm512_testn_epi32_mask(id, id), _mm512_set1_epi32(-1));
    }
    if (all16(ids + i, slot)) {
      metres8(r, window + i, metres + i);
      metres8(r, window + i + 8, metres + i + 8);
      continue;
    }
    for (size_t h = i; h < i + 16; h += 8) {
      const Slots8 s = slotsOf(ids + h, rows);
      if (s.first_lanes == 0xff) {
        if (s.first != slot) slot = s.first, r = rowsOf(rows, slot);
        metres8(r, window + h, metres + h);
      } else {
        Groups8 g;
        metres8(mixedRows(s, rows, g), window + h, metres + h);
      }
    }
  }
  if (kMask) *largest = _mm512_reduce_max_epu32(top);
  return i;
}

VIPER_AVX512 size_t depthMetresAvx512(const uint32_t* ids, const float* window, size_t n, const DepthRows& rows,
                                      float* metres) {
  return metresBlocks<false>(ids, window, n, rows, metres, nullptr, nullptr);
}

VIPER_AVX512 size_t depthMetresMaskingAvx512(const uint32_t* ids, const float* window, size_t n,
                                             const DepthRows& rows, float* metres, int32_t* primitives,
                                             uint32_t& largest) {
  return metresBlocks<true>(ids, window, n, rows, metres, primitives, &largest);
}

VIPER_AVX512 size_t windowDepthAvx512(const uint32_t* ids, const float* metres, size_t n, const DepthRows& rows,
                                      float* window, uint32_t* good, uint32_t* bad) {
  SlotCounts counter{good, bad};
  size_t i = 0;
  uint32_t slot = 0;
  Rows8 r = rowsOf(rows, slot);
  for (; i + 16 <= n; i += 16) {
    if (all16(ids + i, slot)) {
      const uint32_t ok = window8(r, metres + i, window + i) | uint32_t{window8(r, metres + i + 8, window + i + 8)}
                                                                   << 8;
      counter.add(slot, 0xffff, ok);
      continue;
    }
    for (size_t h = i; h < i + 16; h += 8) {
      const Slots8 s = slotsOf(ids + h, rows);
      if (s.first_lanes == 0xff) {
        if (s.first != slot) slot = s.first, r = rowsOf(rows, slot);
        counter.add(slot, 0xff, window8(r, metres + h, window + h));
      } else {
        Groups8 g;
        const __mmask8 ok = window8(mixedRows(s, rows, g), metres + h, window + h);
        for (int k = 0; k < g.count; ++k) counter.add(g.slot[k], g.lanes[k], ok);
      }
    }
  }
  counter.flush();
  return i;
}

}  // namespace pixel_kernels
}  // namespace viper

#endif
