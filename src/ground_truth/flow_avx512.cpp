// The AVX-512 block kernel of flow (flow_kernel.h): 16 pixels a step, the same operations in the
// same order as the AVX2 kernel's 8, so that both give the same flow bit for bit. On CPUs with
// full-width AVX-512 units it does twice the work per instruction; masks replace the blends.
#include "flow_kernel.h"

#ifdef VIPER_X86
#include <immintrin.h>

// GCC 12's AVX-512 intrinsics initialise their undefined operands from themselves, which
// -Wmaybe-uninitialized reports at every use (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <algorithm>

namespace viper {
namespace flow_detail {
namespace {

#define VIPER_AVX512 __attribute__((target("avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt")))
#define VIPER_AVX512_INLINE \
  __attribute__((target("avx512f,avx512bw,avx512vl,avx512dq,avx2,fma,popcnt"), always_inline)) inline

// b's depth at the 16 pixel indices q (all in 0..n_b-1, n_b >= 32): the targets of 16 neighbouring
// pixels nearly always lie within 32 consecutive pixels of b, which two loads and one two-table
// permute fetch; a gather otherwise.
VIPER_AVX512_INLINE __m512 depthAt16(const float* depth_b, int n_b, __m512i q) {
  const int start = std::min(std::max(_mm_cvtsi128_si32(_mm512_castsi512_si128(q)) - 8, 0), n_b - 32);
  const __m512i i = _mm512_sub_epi32(q, _mm512_set1_epi32(start));
  if (_mm512_test_epi32_mask(i, _mm512_set1_epi32(~31))) return _mm512_i32gather_ps(q, depth_b, 4);
  return _mm512_permutex2var_ps(_mm512_loadu_ps(depth_b + start), i, _mm512_loadu_ps(depth_b + start + 16));
}

// What rigid16 needs of frame b and the options, held in locals (see Avx2Target).
struct Avx512Target {
  const float* depth_b;
  int n_b;  // b's pixel count
  __m512 x_end, y_end, last_x, last_y, occ_rel, occ_abs;
  __m512i width_v;
};

// rigid8 of flow_avx2.cpp for 16 pixels: flow (u, v), b's pixel index q (clamped into b) and the
// least depth of b there that does not hide the point (NaN where the point is outside b).
template <bool kMetres>
VIPER_AVX512_INLINE void rigid16(const DrawMapping& m, const Avx512Target& t, __m512 xf, __m512 yf, __m512 g,
                                 __m512& u, __m512& v, __m512i& q, __m512& limit, __mmask16& front) {
  const RowForms& f = m.at_row;
  const __m512 quadratic =
      _mm512_fmadd_ps(_mm512_fmadd_ps(_mm512_set1_ps(f.u2), xf, _mm512_set1_ps(f.u1)), xf, _mm512_set1_ps(f.u0));
  const __m512 linear = _mm512_fmadd_ps(_mm512_set1_ps(f.ue1), xf, _mm512_set1_ps(f.ue0));
  __m512 u_cw, v_cw, cw, co;
  if (kMetres) {
    u_cw = _mm512_fmadd_ps(quadratic, g, linear);
    v_cw = _mm512_fmadd_ps(_mm512_fmadd_ps(_mm512_set1_ps(f.vx), xf, _mm512_set1_ps(f.v0)), g, _mm512_set1_ps(f.ve));
    cw = _mm512_fmadd_ps(_mm512_fmadd_ps(_mm512_set1_ps(f.wx), xf, _mm512_set1_ps(f.w0)), g, _mm512_set1_ps(f.we));
    co = _mm512_fmadd_ps(_mm512_fmadd_ps(_mm512_set1_ps(f.ox), xf, _mm512_set1_ps(f.o0)), g, _mm512_set1_ps(f.oe));
  } else {
    u_cw = _mm512_fmadd_ps(linear, g, quadratic);
    v_cw = _mm512_fmadd_ps(_mm512_set1_ps(f.vx), xf, _mm512_fmadd_ps(_mm512_set1_ps(f.ve), g, _mm512_set1_ps(f.v0)));
    cw = _mm512_fmadd_ps(_mm512_set1_ps(f.wx), xf, _mm512_fmadd_ps(_mm512_set1_ps(f.we), g, _mm512_set1_ps(f.w0)));
    co = _mm512_fmadd_ps(_mm512_set1_ps(f.ox), xf, _mm512_fmadd_ps(_mm512_set1_ps(f.oe), g, _mm512_set1_ps(f.o0)));
  }
  const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f), minus_half = _mm512_set1_ps(-0.5f);
  const __m512 r = _mm512_div_ps(_mm512_set1_ps(1.0f), _mm512_mul_ps(cw, co));
  const __m512 inv_cw = _mm512_mul_ps(co, r), depth = _mm512_mul_ps(cw, _mm512_mul_ps(cw, r));
  u = _mm512_mul_ps(u_cw, inv_cw);
  v = _mm512_mul_ps(v_cw, inv_cw);
  const __m512 xb = _mm512_add_ps(u, xf), yb = _mm512_add_ps(v, yf);
  front = _mm512_cmp_ps_mask(depth, _mm512_set1_ps(m.near_b), _CMP_GT_OQ);
  const __mmask16 inside = front & _mm512_cmp_ps_mask(xb, minus_half, _CMP_GE_OQ) &
                           _mm512_cmp_ps_mask(yb, minus_half, _CMP_GE_OQ) & _mm512_cmp_ps_mask(xb, t.x_end, _CMP_LT_OQ) &
                           _mm512_cmp_ps_mask(yb, t.y_end, _CMP_LT_OQ);
  // Clamped (NaN becomes 0: max returns its second operand) so that every lane may be looked up.
  const __m512i xi = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(_mm512_add_ps(xb, half), zero), t.last_x));
  const __m512i yi = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(_mm512_add_ps(yb, half), zero), t.last_y));
  q = _mm512_add_epi32(_mm512_mullo_epi32(yi, t.width_v), xi);
  _mm_prefetch(reinterpret_cast<const char*>(t.depth_b + _mm_cvtsi128_si32(_mm512_castsi512_si128(q)) + 16),
               _MM_HINT_T0);
  limit = _mm512_mask_blend_ps(inside, _mm512_set1_ps(kNaN), _mm512_fmsub_ps(depth, t.occ_rel, t.occ_abs));
}

// Stores 16 pixels' flow at uv, NaN where there is no surface.
VIPER_AVX512_INLINE void storeFlow16(__m512 u, __m512 v, __mmask16 surface, float* uv) {
  const __m512 nan = _mm512_set1_ps(kNaN);
  u = _mm512_mask_blend_ps(surface, nan, u);
  v = _mm512_mask_blend_ps(surface, nan, v);
  const __m512i lo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const __m512i hi = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  _mm512_storeu_ps(uv, _mm512_permutex2var_ps(u, lo, v));
  _mm512_storeu_ps(uv + 16, _mm512_permutex2var_ps(u, hi, v));
}

// avx2Row in blocks of 16 (see there): a block of one rigid draw at once, a block of several
// draws draw by draw under masks, non-rigid lanes redone one at a time; then b's depth and the mask.
template <bool kMetres>
VIPER_AVX512 int avx512Row(const FlowKernel& k, int y, double ndc_y, int x0, Counts& n) {
  const FlowKernel::Row r = k.rowAt(y);
  const int width = k.width;
  const Avx512Target t{k.depth_b,
                       width * k.height,
                       _mm512_set1_ps(width - 0.5f),
                       _mm512_set1_ps(k.height - 0.5f),
                       _mm512_set1_ps(static_cast<float>(width - 1)),
                       _mm512_set1_ps(static_cast<float>(k.height - 1)),
                       _mm512_set1_ps(k.occ_rel),
                       _mm512_set1_ps(k.occ_abs),
                       _mm512_set1_epi32(width)};
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f), nan = _mm512_set1_ps(kNaN);
  const __m512 infinity = _mm512_set1_ps(kInfinity);
  const __m512 yf = _mm512_set1_ps(static_cast<float>(y));
  __m512 xf = _mm512_add_ps(_mm512_setr_ps(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                            _mm512_set1_ps(static_cast<float>(x0)));
  const int end = width & ~15;
  int n_pending = 0;
  Counts blocks;
  for (int x = x0; x < end; x += 16, xf = _mm512_add_ps(xf, _mm512_set1_ps(16.0f))) {
    const __m512i id = _mm512_loadu_si512(r.ids + x);
    const __m512 d = _mm512_loadu_ps(r.depth + x);
    // A surface: window depth in [0, 1), or metres positive and finite.
    const __mmask16 surface =
        kMetres ? _mm512_cmp_ps_mask(d, zero, _CMP_GT_OQ) & _mm512_cmp_ps_mask(d, infinity, _CMP_LT_OQ)
                : _mm512_cmp_ps_mask(d, zero, _CMP_GE_OQ) & _mm512_cmp_ps_mask(d, one, _CMP_LT_OQ);
    const unsigned surface_bits = surface;
    const __m512 g = kMetres ? d : _mm512_sub_ps(one, d);
    const uint32_t first = r.ids[x];
    DrawMapping& m = r.mappingOf(first);
    const unsigned first_bits = _mm512_cmpeq_epi32_mask(id, _mm512_set1_epi32(static_cast<int>(first)));
    __m512 u, v, limit;
    __m512i q;
    __mmask16 front;
    if (first_bits == 0xffff && m.kind == DrawMapping::kRigid) {
      FlowKernel::countLanes(m, first_bits, surface_bits, x, r.pending, n_pending, blocks);
      m.toRow(y, ndc_y);
      rigid16<kMetres>(m, t, xf, yf, g, u, v, q, limit, front);
      blocks.behind_rigid += __builtin_popcount(surface_bits & ~static_cast<unsigned>(front) & 0xffffu);
    } else {
      u = v = limit = nan;
      front = 0xffff;  // lanes of other draws: as they are
      q = _mm512_setzero_si512();
      for (unsigned remaining = 0xffff; remaining;) {
        const uint32_t draw = r.ids[x + __builtin_ctz(remaining)];
        const __mmask16 lanes = _mm512_cmpeq_epi32_mask(id, _mm512_set1_epi32(static_cast<int>(draw)));
        const unsigned bits = lanes;
        remaining &= ~bits;
        DrawMapping& dm = r.mappingOf(draw);
        FlowKernel::countLanes(dm, bits, surface_bits, x, r.pending, n_pending, blocks);
        if (dm.kind != DrawMapping::kRigid) continue;
        dm.toRow(y, ndc_y);
        __m512 du, dv, dlimit;
        __m512i dq;
        __mmask16 dfront;
        rigid16<kMetres>(dm, t, xf, yf, g, du, dv, dq, dlimit, dfront);
        blocks.behind_rigid += __builtin_popcount(surface_bits & bits & ~static_cast<unsigned>(dfront) & 0xffffu);
        front = static_cast<__mmask16>((front & ~bits) | (dfront & bits));
        u = _mm512_mask_blend_ps(lanes, u, du);
        v = _mm512_mask_blend_ps(lanes, v, dv);
        limit = _mm512_mask_blend_ps(lanes, limit, dlimit);
        q = _mm512_mask_blend_epi32(lanes, q, dq);
      }
    }
    storeFlow16(u, v, surface & front, r.uv + 2 * x);
    _mm512_storeu_si512(r.q + x, q);
    _mm512_storeu_ps(r.limit + x, _mm512_mask_blend_ps(surface, nan, limit));
  }
  for (int x = x0; x < end; x += 16) {
    const __m512 limit = _mm512_loadu_ps(r.limit + x);
    const __m512 there = depthAt16(t.depth_b, t.n_b, _mm512_loadu_si512(r.q + x));
    // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
    const __mmask16 seen = _mm512_cmp_ps_mask(limit, limit, _CMP_ORD_Q) & _mm512_cmp_ps_mask(there, limit, _CMP_NLT_UQ);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(r.visible + x), _mm_movm_epi8(seen));
  }
  k.finishRow(y, ndc_y, n_pending, blocks, n);
  return end;
}

}  // namespace

VIPER_AVX512 int FlowKernel::avx512Pixels(int y, double ndc_y, int x0, Counts& n) const {
  return metres ? avx512Row<true>(*this, y, ndc_y, x0, n) : avx512Row<false>(*this, y, ndc_y, x0, n);
}

}  // namespace flow_detail
}  // namespace viper
#endif
