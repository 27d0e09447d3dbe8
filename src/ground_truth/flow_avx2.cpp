// The AVX2 + FMA block kernel of flow (flow_kernel.h): 8 pixels a step.
#include "flow_kernel.h"

#ifdef VIPER_X86
#include <immintrin.h>

#include <algorithm>
#include <cstdint>

namespace viper {
namespace flow_detail {
namespace {

#define VIPER_AVX2 __attribute__((target("avx2,fma,popcnt")))
#define VIPER_AVX2_INLINE __attribute__((target("avx2,fma,popcnt"), always_inline)) inline

// b's depth at the 8 pixel indices q (all in 0..n_b-1, n_b >= 16). Gathers are slow; the targets
// of 8 neighbouring pixels nearly always lie within 16 consecutive pixels of b, which two loads and
// two permutes fetch.
VIPER_AVX2_INLINE __m256 depthAt(const float* depth_b, int n_b, __m256i q) {
  const int start = std::min(std::max(_mm256_cvtsi256_si32(q) - 4, 0), n_b - 16);
  const __m256i i = _mm256_sub_epi32(q, _mm256_set1_epi32(start));
  if (!_mm256_testz_si256(i, _mm256_set1_epi32(~15))) return _mm256_i32gather_ps(depth_b, q, 4);
  const __m256 lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(depth_b + start), i);
  const __m256 hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(depth_b + start + 8), i);
  return _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_slli_epi32(i, 28)));
}

// What rigid8 needs of frame b and the options, as vectors, held in locals: through the uint8_t
// mask, every store could change a member of FlowKernel, so the compiler would reload those.
struct Avx2Target {
  const float* depth_b;
  int n_b;  // b's pixel count
  __m256 x_end, y_end, last_x, last_y, occ_rel, occ_abs;
  __m256i width_v;
};

// Flow (u, v), b's pixel index q (clamped into b) and the least depth of b there that does not
// hide the point (NaN where the point is outside b), for 8 pixels at xf of row y of a rigid draw
// whose forms are at row y; g = e = 1 - window depth, or metres with forms in 1 / metres
// (kMetres: each form times the metres). Lanes without a surface get garbage.
template <bool kMetres>
VIPER_AVX2_INLINE void rigid8(const DrawMapping& m, const Avx2Target& t, __m256 xf, __m256 yf, __m256 g, __m256& u,
                              __m256& v, __m256i& q, __m256& limit, __m256& front) {
  const RowForms& f = m.at_row;
  const __m256 quadratic =
      _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_set1_ps(f.u2), xf, _mm256_set1_ps(f.u1)), xf, _mm256_set1_ps(f.u0));
  const __m256 linear = _mm256_fmadd_ps(_mm256_set1_ps(f.ue1), xf, _mm256_set1_ps(f.ue0));
  __m256 u_cw, v_cw, cw, co;
  if (kMetres) {
    u_cw = _mm256_fmadd_ps(quadratic, g, linear);
    v_cw = _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_set1_ps(f.vx), xf, _mm256_set1_ps(f.v0)), g, _mm256_set1_ps(f.ve));
    cw = _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_set1_ps(f.wx), xf, _mm256_set1_ps(f.w0)), g, _mm256_set1_ps(f.we));
    co = _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_set1_ps(f.ox), xf, _mm256_set1_ps(f.o0)), g, _mm256_set1_ps(f.oe));
  } else {
    u_cw = _mm256_fmadd_ps(linear, g, quadratic);
    v_cw = _mm256_fmadd_ps(_mm256_set1_ps(f.vx), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.ve), g, _mm256_set1_ps(f.v0)));
    cw = _mm256_fmadd_ps(_mm256_set1_ps(f.wx), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.we), g, _mm256_set1_ps(f.w0)));
    co = _mm256_fmadd_ps(_mm256_set1_ps(f.ox), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.oe), g, _mm256_set1_ps(f.o0)));
  }
  const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f), minus_half = _mm256_set1_ps(-0.5f);
  const __m256 r = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(cw, co));
  const __m256 inv_cw = _mm256_mul_ps(co, r), depth = _mm256_mul_ps(cw, _mm256_mul_ps(cw, r));
  u = _mm256_mul_ps(u_cw, inv_cw);
  v = _mm256_mul_ps(v_cw, inv_cw);
  const __m256 xb = _mm256_add_ps(u, xf), yb = _mm256_add_ps(v, yf);
  front = _mm256_cmp_ps(depth, _mm256_set1_ps(m.near_b), _CMP_GT_OQ);
  const __m256 inside = _mm256_and_ps(
      _mm256_and_ps(front, _mm256_cmp_ps(xb, minus_half, _CMP_GE_OQ)),
      _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(yb, minus_half, _CMP_GE_OQ), _mm256_cmp_ps(xb, t.x_end, _CMP_LT_OQ)),
                    _mm256_cmp_ps(yb, t.y_end, _CMP_LT_OQ)));
  // Clamped (NaN becomes 0) so that every lane may be looked up, inside or not.
  const __m256i xi = _mm256_cvttps_epi32(_mm256_min_ps(_mm256_max_ps(_mm256_add_ps(xb, half), zero), t.last_x));
  const __m256i yi = _mm256_cvttps_epi32(_mm256_min_ps(_mm256_max_ps(_mm256_add_ps(yb, half), zero), t.last_y));
  q = _mm256_add_epi32(_mm256_mullo_epi32(yi, t.width_v), xi);
  // The targets walk along rows of b in an order the hardware prefetcher does not follow; the
  // second pass over the row finds them fetched.
  _mm_prefetch(reinterpret_cast<const char*>(t.depth_b + _mm256_cvtsi256_si32(q) + 8), _MM_HINT_T0);
  limit = _mm256_blendv_ps(_mm256_set1_ps(kNaN), _mm256_fmsub_ps(depth, t.occ_rel, t.occ_abs), inside);
}

// Stores 8 pixels' flow at uv, NaN where there is no surface. Where uv is 16-byte aligned (every row
// of an even width in a malloc'd image), with non-temporal stores: the flow is not read again
// here, and they spare reading its 16 MB a 1080p frame into the cache before writing them
// (BM_FlowFromMetres/1 on the AVX2-only VM of session 18, 6 alternations: 18.4-20.0 -> 17.3-19.0 ms;
// in measure_pipeline.sh the flow node's share did not move beyond the VM's noise).
// The row ends with a store fence (avx2Row).
VIPER_AVX2_INLINE void storeFlow8(__m256 u, __m256 v, __m256 surface, float* uv) {
  const __m256 nan = _mm256_set1_ps(kNaN);
  u = _mm256_blendv_ps(nan, u, surface);
  v = _mm256_blendv_ps(nan, v, surface);
  const __m256 lo = _mm256_unpacklo_ps(u, v), hi = _mm256_unpackhi_ps(u, v);
  if ((reinterpret_cast<uintptr_t>(uv) & 15) == 0) {
    _mm_stream_ps(uv, _mm256_castps256_ps128(lo));
    _mm_stream_ps(uv + 4, _mm256_castps256_ps128(hi));
    _mm_stream_ps(uv + 8, _mm256_extractf128_ps(lo, 1));
    _mm_stream_ps(uv + 12, _mm256_extractf128_ps(hi, 1));
  } else {
    _mm256_storeu_ps(uv, _mm256_permute2f128_ps(lo, hi, 0x20));
    _mm256_storeu_ps(uv + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
  }
}

// How many lanes have a surface whose point is not in front of b's near plane (no flow).
VIPER_AVX2_INLINE int behindLanes(__m256 surface, __m256 front) {
  return __builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(_mm256_andnot_ps(front, surface))));
}

// Which of 8 depths are a surface: window depth in [0, 1), or metres positive and finite (kMetres).
template <bool kMetres>
VIPER_AVX2_INLINE __m256 surfaceOf(__m256 d) {
  const __m256 zero = _mm256_setzero_ps(), infinity = _mm256_set1_ps(kInfinity), one = _mm256_set1_ps(1.0f);
  return kMetres ? _mm256_and_ps(_mm256_cmp_ps(d, zero, _CMP_GT_OQ), _mm256_cmp_ps(d, infinity, _CMP_LT_OQ))
                 : _mm256_and_ps(_mm256_cmp_ps(d, zero, _CMP_GE_OQ), _mm256_cmp_ps(d, one, _CMP_LT_OQ));
}

// Whether the 16 ids at `ids` are all `want`.
VIPER_AVX2_INLINE bool allOf16(const uint32_t* ids, __m256i want) {
  const __m256i lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids));
  const __m256i hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ids + 8));
  return _mm256_movemask_epi8(_mm256_and_si256(_mm256_cmpeq_epi32(lo, want), _mm256_cmpeq_epi32(hi, want))) == -1;
}

// The block at x of row r: its flow (NaN without a surface), and b's pixel and depth limit for the
// row's second pass (NaN: nothing to look up).
VIPER_AVX2_INLINE void storeBlock(const FlowKernel::Row& r, int x, __m256 u, __m256 v, __m256i q, __m256 limit,
                                  __m256 surface) {
  storeFlow8(u, v, surface, r.uv + 2 * x);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(r.q + x), q);
  _mm256_storeu_ps(r.limit + x, _mm256_blendv_ps(_mm256_set1_ps(kNaN), limit, surface));
}

// Row y from x0 in blocks of 8 pixels, as far as whole blocks go; returns where the rest begins. A
// run of one rigid draw (the common case) is computed two blocks a step, a lone block of one rigid
// draw at once; in a block of several draws, each rigid draw is computed over the whole block and
// blended in by lanes, and non-rigid lanes are redone one at a time. Two passes, each with a short
// chain of dependent steps per block, so that the CPU overlaps many blocks: flow and target, then
// b's depth at the target and the mask.
template <bool kMetres>
VIPER_AVX2 int avx2Row(const FlowKernel& k, int y, double ndc_y, int x0, Counts& n) {
  const FlowKernel::Row r = k.rowAt(y);
  const int width = k.width;
  const Avx2Target t{k.depth_b,
                     width * k.height,
                     _mm256_set1_ps(width - 0.5f),
                     _mm256_set1_ps(k.height - 0.5f),
                     _mm256_set1_ps(static_cast<float>(width - 1)),
                     _mm256_set1_ps(static_cast<float>(k.height - 1)),
                     _mm256_set1_ps(k.occ_rel),
                     _mm256_set1_ps(k.occ_abs),
                     _mm256_set1_epi32(width)};
  const __m256 one = _mm256_set1_ps(1.0f), nan = _mm256_set1_ps(kNaN);
  const __m256 yf = _mm256_set1_ps(static_cast<float>(y));
  __m256 xf = _mm256_add_ps(_mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_ps(static_cast<float>(x0)));
  const int end = width & ~7;
  int n_pending = 0;
  Counts blocks;
  for (int x = x0; x < end;) {
    // The block's first draw, for the run and for the block alike.
    const uint32_t first = r.ids[x];
    DrawMapping& m = r.mappingOf(first);
    const __m256i want = _mm256_set1_epi32(static_cast<int>(first));
    // A run of one rigid draw (the common case: a draw's rows run ~100 pixels), two blocks a step:
    // the draw's lookup and counts once a run, and two independent chains of dependent steps (the
    // division the longest) for the CPU to overlap. The same arithmetic as a block at a time:
    // BM_FlowForwardAndBackwardCapture/1/0 on the AVX2-only VM of session 21, alternated with it,
    // 14.5 -> 12.6 ms at best of 25 runs, 18.3 -> 16.9 ms in the median.
    if (x + 16 <= end && m.kind == DrawMapping::kRigid && allOf16(r.ids + x, want)) {
      m.toRow(y, ndc_y);
      int with = 0, pixels = 0, behind = 0;
      do {
        const __m256 d0 = _mm256_loadu_ps(r.depth + x), d1 = _mm256_loadu_ps(r.depth + x + 8);
        const __m256 surface0 = surfaceOf<kMetres>(d0), surface1 = surfaceOf<kMetres>(d1);
        with += __builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(surface0))) +
                __builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(surface1)));
        pixels += 16;
        const __m256 xf1 = _mm256_add_ps(xf, _mm256_set1_ps(8.0f));
        __m256 u0, v0, limit0, front0, u1, v1, limit1, front1;
        __m256i q0, q1;
        rigid8<kMetres>(m, t, xf, yf, kMetres ? d0 : _mm256_sub_ps(one, d0), u0, v0, q0, limit0, front0);
        rigid8<kMetres>(m, t, xf1, yf, kMetres ? d1 : _mm256_sub_ps(one, d1), u1, v1, q1, limit1, front1);
        behind += behindLanes(surface0, front0) + behindLanes(surface1, front1);
        storeBlock(r, x, u0, v0, q0, limit0, _mm256_and_ps(surface0, front0));
        storeBlock(r, x + 8, u1, v1, q1, limit1, _mm256_and_ps(surface1, front1));
        x += 16, xf = _mm256_add_ps(xf, _mm256_set1_ps(16.0f));
      } while (x + 16 <= end && allOf16(r.ids + x, want));
      m.with_depth += with, m.without_depth += pixels - with;  // as countLanes for a rigid draw
      blocks.rigid += with, blocks.no_surface += pixels - with, blocks.behind_rigid += behind;
      continue;
    }
    const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.ids + x));
    const __m256 d = _mm256_loadu_ps(r.depth + x);
    const __m256 surface = surfaceOf<kMetres>(d);
    const unsigned surface_bits = static_cast<unsigned>(_mm256_movemask_ps(surface));
    const __m256 g = kMetres ? d : _mm256_sub_ps(one, d);
    const unsigned first_bits =
        static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(id, want))));
    __m256 u, v, limit, front;
    __m256i q;
    if (first_bits == 0xff && m.kind == DrawMapping::kRigid) {
      FlowKernel::countLanes(m, first_bits, surface_bits, x, r.pending, n_pending, blocks);
      m.toRow(y, ndc_y);
      rigid8<kMetres>(m, t, xf, yf, g, u, v, q, limit, front);
      blocks.behind_rigid += behindLanes(surface, front);
    } else {
      u = v = limit = nan;
      front = _mm256_castsi256_ps(_mm256_set1_epi32(-1));  // lanes of other draws: as they are
      q = _mm256_setzero_si256();
      for (unsigned remaining = 0xff; remaining;) {
        const uint32_t draw = r.ids[x + __builtin_ctz(remaining)];
        const __m256 lanes = _mm256_castsi256_ps(_mm256_cmpeq_epi32(id, _mm256_set1_epi32(static_cast<int>(draw))));
        const unsigned bits = static_cast<unsigned>(_mm256_movemask_ps(lanes));
        remaining &= ~bits;
        DrawMapping& dm = r.mappingOf(draw);
        FlowKernel::countLanes(dm, bits, surface_bits, x, r.pending, n_pending, blocks);
        if (dm.kind != DrawMapping::kRigid) continue;
        dm.toRow(y, ndc_y);
        __m256 du, dv, dlimit, dfront;
        __m256i dq;
        rigid8<kMetres>(dm, t, xf, yf, g, du, dv, dq, dlimit, dfront);
        blocks.behind_rigid += behindLanes(_mm256_and_ps(surface, lanes), dfront);
        front = _mm256_blendv_ps(front, dfront, lanes);
        u = _mm256_blendv_ps(u, du, lanes);
        v = _mm256_blendv_ps(v, dv, lanes);
        limit = _mm256_blendv_ps(limit, dlimit, lanes);
        q = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(q), _mm256_castsi256_ps(dq), lanes));
      }
    }
    storeBlock(r, x, u, v, q, limit, _mm256_and_ps(surface, front));
    x += 8, xf = _mm256_add_ps(xf, _mm256_set1_ps(8.0f));
  }
  for (int x = x0; x < end; x += 8) {
    const __m256 limit = _mm256_loadu_ps(r.limit + x);
    const __m256 there = depthAt(t.depth_b, t.n_b, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.q + x)));
    // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
    const __m256i seen = _mm256_castps_si256(
        _mm256_and_ps(_mm256_cmp_ps(limit, limit, _CMP_ORD_Q), _mm256_cmp_ps(there, limit, _CMP_NLT_UQ)));
    const __m256i bytes = _mm256_packs_epi16(_mm256_packs_epi32(seen, seen), _mm256_setzero_si256());
    _mm_storel_epi64(reinterpret_cast<__m128i*>(r.visible + x),
                     _mm_unpacklo_epi32(_mm256_castsi256_si128(bytes), _mm256_extracti128_si256(bytes, 1)));
  }
  _mm_sfence();  // the row's non-temporal stores (storeFlow8) before any later store
  k.finishRow(y, ndc_y, n_pending, blocks, n);
  return end;
}

}  // namespace

VIPER_AVX2 int FlowKernel::avx2Pixels(int y, double ndc_y, int x0, Counts& n) const {
  return metres ? avx2Row<true>(*this, y, ndc_y, x0, n) : avx2Row<false>(*this, y, ndc_y, x0, n);
}

}  // namespace flow_detail
}  // namespace viper
#endif
