#include "viper/core/flow.h"

#include <Eigen/LU>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define VIPER_FLOW_AVX2 1
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

namespace viper {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();

using WorldBytes = std::array<float, 16>;
WorldBytes worldBytes(const DrawRecord& d) {
  WorldBytes w;
  std::memcpy(w.data(), d.world.data(), sizeof(w));
  return w;
}

// A rigid draw's mapping along one row of a, in float. With e = 1 - window depth and cw, co as in
// DrawMapping: u cw = u0 + x (u1 + x u2) + e (ue0 + x ue1), v cw = v0 + x vx + e ve,
// cw = w0 + x wx + e we, co = o0 + x ox + e oe. The flow itself (not b's pixel coordinates) is
// formed so that float keeps the precision of the flow, not of the pixel position.
struct RowForms {
  float u0, u1, u2, ue0, ue1, v0, vx, ve, w0, wx, we, o0, ox, oe;
};

// How the pixels of one draw of frame a map into frame b.
struct DrawMapping {
  enum Kind : uint8_t { kNoDraw, kNone, kRigid, kNonRigid, kMissing } kind = kNone;
  // Rigid: inverse(pvw_a) maps ndc_a to the object point times 1 / clip_w_a, so pvw_b times it is
  // clip_b / clip_w_a. Four affine forms of (ndc_y, x, e) give px, py (b's pixel coordinates times
  // cw), cw (clip_w_b / clip_w_a) and co (1 / clip_w_a / depth scale of b): b's pixel is
  // (px, py) / cw and the point's depth in b cw / co. Depth enters as e = 1 - window depth, which is
  // exact for window depths >= 0.5: in e the forms stay well-conditioned for far surfaces, where in
  // the window depth itself large terms would cancel.
  enum Form { kPx, kPy, kCw, kCo };
  double form_c[4] = {}, form_y[4] = {}, form_x[4] = {}, form_e[4] = {};
  RowForms at_row{};
  int row = -1;
  // Non-rigid.
  const std::vector<uint32_t>* indices = nullptr;
  const std::vector<float>* clip_a = nullptr;
  const std::vector<float>* clip_b = nullptr;
  double depth_scale_b = 1.0;  // clip w -> metres along b's optical axis

  // Sets at_row to row y (at ndc_y); each coefficient is rounded to float once, from double.
  void toRow(int y, double ndc_y) {
    if (row == y) return;
    row = y;
    double c[4];
    for (int f = 0; f < 4; ++f) c[f] = form_c[f] + form_y[f] * ndc_y;
    auto f32 = [](double v) { return static_cast<float>(v); };
    at_row = {f32(c[kPx]),
              f32(form_x[kPx] - c[kCw]),
              f32(-form_x[kCw]),
              f32(form_e[kPx]),
              f32(-form_e[kCw]),
              f32(c[kPy] - y * c[kCw]),
              f32(form_x[kPy] - y * form_x[kCw]),
              f32(form_e[kPy] - y * form_e[kCw]),
              f32(c[kCw]),
              f32(form_x[kCw]),
              f32(form_e[kCw]),
              f32(c[kCo]),
              f32(form_x[kCo]),
              f32(form_e[kCo])};
  }
};

// Sets the rigid forms of `m` from M = pvw_b * inverse(pvw_a) and N, the last row of
// inverse(pvw_a), for frames of width x height pixels.
void setRigidForms(DrawMapping& m, const Eigen::Matrix4d& M, const Eigen::RowVector4d& N, double width,
                   double height) {
  const double half_w = 0.5 * width, half_h = 0.5 * height;
  // Each a row vector over ndc_a = (2 (x + 0.5) / width - 1, ndc_y, 1 - 2 e, 1).
  const Eigen::RowVector4d forms[4] = {half_w * M.row(0) + (half_w - 0.5) * M.row(3),
                                       (half_h - 0.5) * M.row(3) - half_h * M.row(1), M.row(3),
                                       N / m.depth_scale_b};
  for (int f = 0; f < 4; ++f) {
    const Eigen::RowVector4d& r = forms[f];
    m.form_c[f] = r[0] * (1.0 / width - 1.0) + r[2] + r[3];
    m.form_y[f] = r[1];
    m.form_x[f] = 2.0 * r[0] / width;
    m.form_e[f] = -2.0 * r[2];
  }
}

Eigen::Vector4d clipAt(const std::vector<float>& c, uint32_t vertex) {
  const size_t i = 4 * static_cast<size_t>(vertex);
  return Eigen::Vector4d(c[i], c[i + 1], c[i + 2], c[i + 3]);
}

// The point of a non-rigid pixel in b's clip space: screen-space barycentrics of the pixel
// center in its triangle, made perspective-correct with the vertices' w, applied to b's vertices.
// Inlined: called once per non-rigid pixel, and its divisions overlap with the caller's.
__attribute__((always_inline)) inline std::optional<Eigen::Vector4d> nonRigidClip(const DrawMapping& m, uint32_t primitive,
                                                                                double ndc_x, double ndc_y) {
  const size_t t = 3 * static_cast<size_t>(primitive);
  const auto& idx = *m.indices;
  const size_t verts = m.clip_a->size() / 4;
  if (t + 2 >= idx.size() || idx[t] >= verts || idx[t + 1] >= verts || idx[t + 2] >= verts) return std::nullopt;
  const Eigen::Vector4d c0 = clipAt(*m.clip_a, idx[t]), c1 = clipAt(*m.clip_a, idx[t + 1]),
                        c2 = clipAt(*m.clip_a, idx[t + 2]);
  const Eigen::Vector2d s0 = c0.head<2>() / c0.w(), s1 = c1.head<2>() / c1.w(), s2 = c2.head<2>() / c2.w();
  const Eigen::Vector2d q(ndc_x, ndc_y), e1 = s1 - s0, e2 = s2 - s0, dq = q - s0;
  const double area = e1.x() * e2.y() - e1.y() * e2.x();
  if (area == 0.0) return std::nullopt;
  const double l1 = (dq.x() * e2.y() - dq.y() * e2.x()) / area;
  const double l2 = (e1.x() * dq.y() - e1.y() * dq.x()) / area;
  const double b0 = (1.0 - l1 - l2) / c0.w(), b1 = l1 / c1.w(), b2 = l2 / c2.w();
  return (b0 * clipAt(*m.clip_b, idx[t]) + b1 * clipAt(*m.clip_b, idx[t + 1]) + b2 * clipAt(*m.clip_b, idx[t + 2])) /
         (b0 + b1 + b2);
}

struct Counts {
  size_t rigid = 0, non_rigid = 0, no_surface = 0, no_assoc = 0, missing = 0;
};

// One flow computation a -> b over plain pointers: stores through the uint8_t mask may alias
// anything that lives in memory, which would force reloads of state held in vectors.
struct FlowKernel {
  const uint32_t* ids;        // a's draw ids
  const float* depth_a;       // a's window depth
  const uint32_t* primitives;  // a's primitive ids
  const float* depth_b;       // b's depth in metres, NaN = no surface
  int width, height;
  float occ_rel, occ_abs;  // visible when depth_b >= depth * occ_rel - occ_abs
  DrawMapping* maps;        // by draw id; maps[0] is kNoDraw
  uint32_t n_draws;
  float* uv;
  uint8_t* visible;
  // A row's worth each: b's pixel index and depth limit of rigid targets, and pixels to redo.
  int32_t* row_q;
  float* row_limit;
  int32_t* row_pending;

  DrawMapping& mappingOf(uint32_t id) const { return maps[id <= n_draws ? id : 0]; }

  // Writes pixel p = (x, y) of a rigid draw, which must be at row y; returns whether it has a surface.
  bool rigidPixel(const DrawMapping& m, int x, int y, size_t p) const {
    const RowForms& f = m.at_row;
    const float d = depth_a[p];
    const float xf = static_cast<float>(x), e = 1.0f - d;
    const float u_cw = (f.u2 * xf + f.u1) * xf + f.u0 + (f.ue1 * xf + f.ue0) * e;
    const float v_cw = f.vx * xf + (f.ve * e + f.v0);
    const float cw = f.wx * xf + (f.we * e + f.w0), co = f.ox * xf + (f.oe * e + f.o0);
    const float r = 1.0f / (cw * co);
    const float inv_cw = co * r, depth = cw * (cw * r);
    const float u = u_cw * inv_cw, v = v_cw * inv_cw;
    const float xb = u + xf, yb = v + static_cast<float>(y);
    bool seen = false;
    if (depth > 0.0f && xb >= -0.5f && yb >= -0.5f && xb < width - 0.5f && yb < height - 0.5f) {
      const size_t q = static_cast<size_t>(yb + 0.5f) * width + static_cast<size_t>(xb + 0.5f);
      // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
      seen = !(depth_b[q] < depth * occ_rel - occ_abs);
    }
    const bool surface = d >= 0.0f && d < 1.0f;
    uv[2 * p] = surface ? u : kNaN;
    uv[2 * p + 1] = surface ? v : kNaN;
    visible[p] = surface && seen ? 255 : 0;
    return surface;
  }

  // Whether a point at (xb, yb) in b's pixel coordinates and `depth` metres in front of b's camera
  // is inside b and not behind b's depth there.
  uint8_t visibleAt(double xb, double yb, double depth) const {
    if (!(depth > 0.0 && xb >= -0.5 && yb >= -0.5 && xb < width - 0.5 && yb < height - 0.5)) return 0;
    const size_t q = static_cast<size_t>(yb + 0.5) * width + static_cast<size_t>(xb + 0.5);
    return !(depth_b[q] < depth * occ_rel - occ_abs) ? 255 : 0;
  }

  void undefined(size_t p) const {
    uv[2 * p] = uv[2 * p + 1] = kNaN;
    visible[p] = 0;
  }

  // Pixel (x, y) of any draw but a rigid one.
  void otherPixel(const DrawMapping& m, int x, int y, double ndc_y, Counts& n) const {
    const size_t p = static_cast<size_t>(y) * width + x;
    const float d = depth_a[p];
    if (m.kind == DrawMapping::kNoDraw || !(d >= 0.0f && d < 1.0f)) {
      ++n.no_surface;
      undefined(p);
    } else if (m.kind != DrawMapping::kNonRigid) {
      ++(m.kind == DrawMapping::kNone ? n.no_assoc : n.missing);
      undefined(p);
    } else if (auto clip_b = nonRigidClip(m, primitives[p], 2.0 * (x + 0.5) / width - 1.0, ndc_y)) {
      const double inv_w = 1.0 / clip_b->w();
      const double xb = (clip_b->x() * inv_w + 1.0) * 0.5 * width - 0.5;
      const double yb = (1.0 - clip_b->y() * inv_w) * 0.5 * height - 0.5;
      uv[2 * p] = static_cast<float>(xb - x);
      uv[2 * p + 1] = static_cast<float>(yb - y);
      visible[p] = visibleAt(xb, yb, clip_b->w() * m.depth_scale_b);
      ++n.non_rigid;
    } else {
      ++n.missing;
      undefined(p);
    }
  }

  // Pixels x0..x1-1 of row y, one at a time.
  void scalarPixels(int y, double ndc_y, int x0, int x1, Counts& n) const {
    const size_t row = static_cast<size_t>(y) * width;
    for (int x = x0; x < x1; ++x) {
      DrawMapping& m = mappingOf(ids[row + x]);
      if (m.kind == DrawMapping::kRigid) {
        m.toRow(y, ndc_y);
        if (rigidPixel(m, x, y, row + x))
          ++n.rigid;
        else
          ++n.no_surface;
      } else {
        otherPixel(m, x, y, ndc_y, n);
      }
    }
  }

#ifdef VIPER_FLOW_AVX2
  int avx2Pixels(int y, double ndc_y, Counts& n) const;
#endif
};

#ifdef VIPER_FLOW_AVX2
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
// whose forms are at row y; e = 1 - window depth. Lanes without a surface get garbage.
VIPER_AVX2_INLINE void rigid8(const DrawMapping& m, const Avx2Target& t, __m256 xf, __m256 yf, __m256 e, __m256& u,
                              __m256& v, __m256i& q, __m256& limit) {
  const RowForms& f = m.at_row;
  const __m256 u_cw = _mm256_fmadd_ps(
      _mm256_fmadd_ps(_mm256_set1_ps(f.ue1), xf, _mm256_set1_ps(f.ue0)), e,
      _mm256_fmadd_ps(_mm256_fmadd_ps(_mm256_set1_ps(f.u2), xf, _mm256_set1_ps(f.u1)), xf, _mm256_set1_ps(f.u0)));
  const __m256 v_cw =
      _mm256_fmadd_ps(_mm256_set1_ps(f.vx), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.ve), e, _mm256_set1_ps(f.v0)));
  const __m256 cw =
      _mm256_fmadd_ps(_mm256_set1_ps(f.wx), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.we), e, _mm256_set1_ps(f.w0)));
  const __m256 co =
      _mm256_fmadd_ps(_mm256_set1_ps(f.ox), xf, _mm256_fmadd_ps(_mm256_set1_ps(f.oe), e, _mm256_set1_ps(f.o0)));
  const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f), minus_half = _mm256_set1_ps(-0.5f);
  const __m256 r = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(cw, co));
  const __m256 inv_cw = _mm256_mul_ps(co, r), depth = _mm256_mul_ps(cw, _mm256_mul_ps(cw, r));
  u = _mm256_mul_ps(u_cw, inv_cw);
  v = _mm256_mul_ps(v_cw, inv_cw);
  const __m256 xb = _mm256_add_ps(u, xf), yb = _mm256_add_ps(v, yf);
  const __m256 inside = _mm256_and_ps(
      _mm256_and_ps(_mm256_cmp_ps(depth, zero, _CMP_GT_OQ), _mm256_cmp_ps(xb, minus_half, _CMP_GE_OQ)),
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

// Stores 8 pixels' flow at uv, NaN where there is no surface.
VIPER_AVX2_INLINE void storeFlow8(__m256 u, __m256 v, __m256 surface, float* uv) {
  const __m256 nan = _mm256_set1_ps(kNaN);
  u = _mm256_blendv_ps(nan, u, surface);
  v = _mm256_blendv_ps(nan, v, surface);
  const __m256 lo = _mm256_unpacklo_ps(u, v), hi = _mm256_unpackhi_ps(u, v);
  _mm256_storeu_ps(uv, _mm256_permute2f128_ps(lo, hi, 0x20));
  _mm256_storeu_ps(uv + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
}

// Row y in blocks of 8 pixels, as far as whole blocks go; returns where the rest begins. A block of
// one rigid draw (the common case) is computed at once; in a block of several draws, each rigid
// draw is computed over the whole block and blended in by lanes, and non-rigid lanes are redone
// one at a time. Two passes, each with a short chain of dependent steps per block, so that the
// CPU overlaps many blocks: flow and target, then b's depth at the target and the mask.
VIPER_AVX2 int FlowKernel::avx2Pixels(int y, double ndc_y, Counts& n) const {
  const size_t row = static_cast<size_t>(y) * width;
  const uint32_t* const row_ids = ids + row;
  const float* const row_depth = depth_a + row;
  float* const row_uv = uv + 2 * row;
  uint8_t* const row_visible = visible + row;
  int32_t* const qs = row_q;
  float* const limits = row_limit;
  int32_t* const pending = row_pending;
  DrawMapping* const by_id = maps;
  const uint32_t last_id = n_draws;
  const Avx2Target t{depth_b,
                     width * height,
                     _mm256_set1_ps(width - 0.5f),
                     _mm256_set1_ps(height - 0.5f),
                     _mm256_set1_ps(static_cast<float>(width - 1)),
                     _mm256_set1_ps(static_cast<float>(height - 1)),
                     _mm256_set1_ps(occ_rel),
                     _mm256_set1_ps(occ_abs),
                     _mm256_set1_epi32(width)};
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), nan = _mm256_set1_ps(kNaN);
  const __m256 yf = _mm256_set1_ps(static_cast<float>(y));
  __m256 xf = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const int end = width & ~7;
  int n_pending = 0;
  size_t n_rigid = 0, n_no_surface = 0, n_no_assoc = 0, n_missing = 0;
  for (int x = 0; x < end; x += 8, xf = _mm256_add_ps(xf, _mm256_set1_ps(8.0f))) {
    const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row_ids + x));
    const __m256 d = _mm256_loadu_ps(row_depth + x);
    const __m256 surface = _mm256_and_ps(_mm256_cmp_ps(d, zero, _CMP_GE_OQ), _mm256_cmp_ps(d, one, _CMP_LT_OQ));
    const unsigned surface_bits = static_cast<unsigned>(_mm256_movemask_ps(surface));
    const __m256 e = _mm256_sub_ps(one, d);
    const uint32_t first = row_ids[x];
    DrawMapping& m = by_id[first <= last_id ? first : 0];
    const unsigned first_bits = static_cast<unsigned>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(id, _mm256_set1_epi32(static_cast<int>(first))))));
    __m256 u, v, limit;
    __m256i q;
    if (first_bits == 0xff && m.kind == DrawMapping::kRigid) {
      m.toRow(y, ndc_y);
      rigid8(m, t, xf, yf, e, u, v, q, limit);
      const int with_surface = __builtin_popcount(surface_bits);
      n_rigid += with_surface;
      n_no_surface += 8 - with_surface;
    } else {
      u = v = limit = nan;
      q = _mm256_setzero_si256();
      unsigned remaining = 0xff;
      while (remaining) {
        const uint32_t draw = row_ids[x + __builtin_ctz(remaining)];
        const __m256 lanes = _mm256_castsi256_ps(_mm256_cmpeq_epi32(id, _mm256_set1_epi32(static_cast<int>(draw))));
        const unsigned bits = static_cast<unsigned>(_mm256_movemask_ps(lanes));
        remaining &= ~bits;
        DrawMapping& dm = by_id[draw <= last_id ? draw : 0];
        const int with_surface = __builtin_popcount(bits & surface_bits);
        const int without = __builtin_popcount(bits & ~surface_bits);
        switch (dm.kind) {
          case DrawMapping::kRigid: {
            dm.toRow(y, ndc_y);
            __m256 du, dv, dlimit;
            __m256i dq;
            rigid8(dm, t, xf, yf, e, du, dv, dq, dlimit);
            u = _mm256_blendv_ps(u, du, lanes);
            v = _mm256_blendv_ps(v, dv, lanes);
            limit = _mm256_blendv_ps(limit, dlimit, lanes);
            q = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(q), _mm256_castsi256_ps(dq), lanes));
            n_rigid += with_surface;
            n_no_surface += without;
            break;
          }
          case DrawMapping::kNonRigid:
            for (unsigned b = bits; b; b &= b - 1) pending[n_pending++] = x + __builtin_ctz(b);
            break;
          case DrawMapping::kNoDraw:
            n_no_surface += with_surface + without;
            break;
          case DrawMapping::kNone:
            n_no_assoc += with_surface;
            n_no_surface += without;
            break;
          case DrawMapping::kMissing:
            n_missing += with_surface;
            n_no_surface += without;
            break;
        }
      }
    }
    storeFlow8(u, v, surface, row_uv + 2 * x);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(qs + x), q);
    _mm256_storeu_ps(limits + x, _mm256_blendv_ps(nan, limit, surface));
  }
  for (int x = 0; x < end; x += 8) {
    const __m256 limit = _mm256_loadu_ps(limits + x);
    const __m256 there = depthAt(t.depth_b, t.n_b, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(qs + x)));
    // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
    const __m256i seen = _mm256_castps_si256(
        _mm256_and_ps(_mm256_cmp_ps(limit, limit, _CMP_ORD_Q), _mm256_cmp_ps(there, limit, _CMP_NLT_UQ)));
    const __m256i bytes = _mm256_packs_epi16(_mm256_packs_epi32(seen, seen), _mm256_setzero_si256());
    _mm_storel_epi64(reinterpret_cast<__m128i*>(row_visible + x),
                     _mm_unpacklo_epi32(_mm256_castsi256_si128(bytes), _mm256_extracti128_si256(bytes, 1)));
  }
  Counts others;
  for (int i = 0; i < n_pending; ++i) otherPixel(mappingOf(row_ids[pending[i]]), pending[i], y, ndc_y, others);
  n.rigid += n_rigid;
  n.non_rigid += others.non_rigid;
  n.no_surface += n_no_surface + others.no_surface;
  n.no_assoc += n_no_assoc;
  n.missing += n_missing + others.missing;
  return end;
}
#endif

}  // namespace

std::vector<int32_t> associateDraws(const CaptureFrame& a, const std::vector<int32_t>& a_ids, const CaptureFrame& b,
                                    const std::vector<int32_t>& b_ids) {
  std::map<std::pair<int32_t, uint64_t>, int32_t> by_object;
  std::map<std::pair<uint64_t, WorldBytes>, int32_t> by_placement;
  std::map<uint64_t, int32_t> by_mesh;  // -2 = the mesh occurs more than once
  for (size_t j = 0; j < b.draws.size(); ++j) {
    const DrawRecord& d = b.draws[j];
    const int32_t id = j < b_ids.size() ? b_ids[j] : 0;
    if (id > 0) by_object.emplace(std::make_pair(id, d.mesh_key), static_cast<int32_t>(j));
    by_placement.emplace(std::make_pair(d.mesh_key, worldBytes(d)), static_cast<int32_t>(j));
    auto [it, inserted] = by_mesh.emplace(d.mesh_key, static_cast<int32_t>(j));
    if (!inserted) it->second = -2;
  }
  std::map<uint64_t, int> a_mesh_count;
  for (const DrawRecord& d : a.draws) ++a_mesh_count[d.mesh_key];

  std::vector<int32_t> out(a.draws.size(), -1);
  for (size_t i = 0; i < a.draws.size(); ++i) {
    const DrawRecord& d = a.draws[i];
    const int32_t id = i < a_ids.size() ? a_ids[i] : 0;
    if (id > 0) {
      auto it = by_object.find({id, d.mesh_key});
      if (it != by_object.end()) out[i] = it->second;
      continue;
    }
    auto it = by_placement.find({d.mesh_key, worldBytes(d)});
    if (it != by_placement.end()) {
      out[i] = it->second;
    } else if (a_mesh_count[d.mesh_key] == 1) {
      auto m = by_mesh.find(d.mesh_key);
      if (m != by_mesh.end() && m->second >= 0) out[i] = m->second;
    }
  }
  return out;
}

FlowField computeFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                      const std::vector<float>& b_depth_m, const MeshRegistry& meshes, const FlowOptions& options,
                      FlowStats* stats_out) {
  FlowField f;
  computeFlow(a, b, a_to_b, b_depth_m, meshes, f, options, stats_out);
  return f;
}

void computeFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                 const std::vector<float>& b_depth_m, const MeshRegistry& meshes, FlowField& f,
                 const FlowOptions& options, FlowStats* stats_out) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument("computeFlow: frame sizes differ (" + std::to_string(a.width) + "x" +
                                std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                                std::to_string(b.height) + ")");
  const size_t n = a.pixelCount();
  if (a_to_b.size() != a.draws.size() || b_depth_m.size() != n || a.draw_ids.size() != n ||
      a.primitive_ids.size() != n || a.depth_window.size() != n)
    throw std::invalid_argument("computeFlow: an input's size does not match its frame");

  // By draw id: maps[0] stands for pixels of no draw.
  std::vector<DrawMapping> maps(a.draws.size() + 1);
  maps[0].kind = DrawMapping::kNoDraw;
  for (size_t i = 0; i < a.draws.size(); ++i) {
    DrawMapping& m = maps[i + 1];
    if (a_to_b[i] < 0 || static_cast<size_t>(a_to_b[i]) >= b.draws.size()) continue;
    const DrawRecord& da = a.draws[i];
    const DrawRecord& db = b.draws[a_to_b[i]];
    m.kind = DrawMapping::kMissing;
    if (db.projection(3, 2) == 0.0f) continue;
    m.depth_scale_b = -1.0 / db.projection(3, 2);
    if (!da.deformed_clip_xyzw.empty() || !db.deformed_clip_xyzw.empty()) {
      const MeshRecord* mesh = meshes.find(da.mesh_key);
      const size_t verts = mesh ? mesh->positions_xyz.size() / 3 : 0;
      if (!mesh || da.deformed_clip_xyzw.size() != 4 * verts || db.deformed_clip_xyzw.size() != 4 * verts) continue;
      m.kind = DrawMapping::kNonRigid;
      m.indices = &mesh->indices;
      m.clip_a = &da.deformed_clip_xyzw;
      m.clip_b = &db.deformed_clip_xyzw;
    } else {
      const Eigen::Matrix4d pvw_a = da.projection.cast<double>() * da.view.cast<double>() * da.world.cast<double>();
      const Eigen::Matrix4d pvw_b = db.projection.cast<double>() * db.view.cast<double>() * db.world.cast<double>();
      Eigen::FullPivLU<Eigen::Matrix4d> lu(pvw_a);
      if (!pvw_a.allFinite() || !pvw_b.allFinite() || !lu.isInvertible()) continue;
      m.kind = DrawMapping::kRigid;
      const Eigen::Matrix4d ndc_a_to_object = lu.inverse();
      setRigidForms(m, pvw_b * ndc_a_to_object, ndc_a_to_object.row(3), a.width, a.height);
    }
  }

  f.width = a.width;
  f.height = a.height;
  f.uv.resize(2 * n);
  f.visible.resize(n);
  std::vector<int32_t> row_q(a.width), row_pending(a.width);
  std::vector<float> row_limit(a.width);
  const FlowKernel kernel{a.draw_ids.data(),
                          a.depth_window.data(),
                          a.primitive_ids.data(),
                          b_depth_m.data(),
                          static_cast<int>(a.width),
                          static_cast<int>(a.height),
                          static_cast<float>(1.0 - options.occlusion_relative),
                          static_cast<float>(options.occlusion_absolute_m),
                          maps.data(),
                          static_cast<uint32_t>(a.draws.size()),
                          f.uv.data(),
                          f.visible.data(),
                          row_q.data(),
                          row_limit.data(),
                          row_pending.data()};
#ifdef VIPER_FLOW_AVX2
  static const bool avx2 =
      __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("popcnt");
#endif
  Counts counts;
  for (int y = 0; y < static_cast<int>(a.height); ++y) {
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / a.height;
    int x = 0;
#ifdef VIPER_FLOW_AVX2
    if (avx2 && n >= 16) x = kernel.avx2Pixels(y, ndc_y, counts);
#endif
    kernel.scalarPixels(y, ndc_y, x, kernel.width, counts);
  }
  FlowStats stats;
  stats.rigid = counts.rigid, stats.non_rigid = counts.non_rigid, stats.no_surface = counts.no_surface;
  stats.no_association = counts.no_assoc, stats.missing_geometry = counts.missing;
  if (stats_out) *stats_out = stats;
}

}  // namespace viper
