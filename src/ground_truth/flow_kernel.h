// Internal to viper_core: how the pixels of one flow computation map into the other frame (set up
// by flow.cpp), and the kernels that compute them: one pixel at a time here, blocks of 8
// (flow_avx2.cpp) and of 16 (flow_avx512.cpp) on CPUs that have those instructions.
#pragma once

#include "viper/ground_truth/flow.h"
#include "x86_kernels.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper {
namespace flow_detail {

const float kNaN = std::numeric_limits<float>::quiet_NaN();

// A rigid draw's mapping along one row of a, in float. With e = 1 - window depth and cw, co as in
// DrawMapping: u cw = u0 + x (u1 + x u2) + e (ue0 + x ue1), v cw = v0 + x vx + e ve,
// cw = w0 + x wx + e we, co = o0 + x ox + e oe. The flow itself (not b's pixel coordinates) is
// formed so that float keeps the precision of the flow, not of the pixel position.
struct RowForms {
  float u0, u1, u2, ue0, ue1, v0, vx, ve, w0, wx, we, o0, ox, oe;
};

// How the pixels of one draw of frame a map into frame b.
struct DrawMapping {
  // kRigidConverted: a rigid draw whose depth comes in metres, under a projection in which window
  // depth is not affine in 1 / metres (an orthographic one, say): each pixel's metres are turned
  // into window depth one at a time (through p22..p33), as windowDepthFromMetres does.
  enum Kind : uint8_t { kNoDraw, kNone, kRigid, kNonRigid, kMissing, kRigidConverted } kind = kNone;
  // Rigid: inverse(pvw_a) maps ndc_a to the object point times 1 / clip_w_a, so pvw_b times it is
  // clip_b / clip_w_a. Four affine forms of (ndc_y, x, e) give px, py (b's pixel coordinates times
  // cw), cw (clip_w_b / clip_w_a) and co (1 / clip_w_a / depth scale of b): b's pixel is
  // (px, py) / cw and the point's depth in b cw / co. Depth enters as e = 1 - window depth, which is
  // exact for window depths >= 0.5: in e the forms stay well-conditioned for far surfaces, where in
  // the window depth itself large terms would cancel.
  enum Form { kPx, kPy, kCw, kCo };
  // When a's depth comes in metres m, a rigid draw's forms are in s = 1 / m instead of e (e is
  // affine in s when the projection's P33 is 0: setMetresForms), and the kernels evaluate each
  // form times m, (c + x ...) m + (e terms): the ratios u, v and depth are those of the forms, and
  // no division by m is needed.
  double form_c[4] = {}, form_y[4] = {}, form_x[4] = {}, form_e[4] = {};
  RowForms at_row{};
  int row = -1;
  // kRigidConverted: rows 2 and 3 of the projection that turns metres into window depth (none:
  // its pixels have no depth).
  bool has_depth_rows = false;
  double p22 = 0, p23 = 0, p32 = 0, p33 = 0;
  // Pixels of this draw with a surface (depth) and without: pixels without depth in a draw that has
  // depth elsewhere are reported (FlowStats::no_depth); a draw with none at all is a background.
  size_t with_depth = 0, without_depth = 0;
  // Non-rigid.
  const std::vector<uint32_t>* indices = nullptr;
  const std::vector<float>* clip_a = nullptr;
  const std::vector<float>* clip_b = nullptr;
  double depth_scale_b = 1.0;  // clip w -> metres along b's optical axis
  // b's near plane (clip z = -w) as a depth in b, at least 0: a point at or before it has no flow
  // (b's camera cannot image it; its projection runs off to infinity at the camera plane).
  float near_b = 0.0f;
  // Non-rigid: the last triangle looked up (nonRigidClip), for the pixels after it in the row that
  // lie in it too: the rows of adj(M) and b's vertices, or none (the triangle maps nothing).
  struct Triangle {
    bool cached = false, maps = false;
    uint32_t primitive = 0;
    double n[9];
    const float* b[3];
  } triangle;

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

// The triangle `primitive` of a non-rigid draw into m.triangle: whether it maps a pixel.
inline bool setTriangle(DrawMapping& m, uint32_t primitive) {
  DrawMapping::Triangle& tri = m.triangle;
  tri.cached = true, tri.primitive = primitive, tri.maps = false;
  const size_t t = 3 * static_cast<size_t>(primitive);
  const auto& idx = *m.indices;
  const size_t verts = m.clip_a->size() / 4;
  if (t + 2 >= idx.size() || idx[t] >= verts || idx[t + 1] >= verts || idx[t + 2] >= verts) return false;
  // Plain doubles: GCC leaves Eigen's small cross and dot products out of line here.
  const float *a0 = m.clip_a->data() + 4 * size_t{idx[t]}, *a1 = m.clip_a->data() + 4 * size_t{idx[t + 1]},
              *a2 = m.clip_a->data() + 4 * size_t{idx[t + 2]};
  const double x0 = a0[0], y0 = a0[1], w0 = a0[3], x1 = a1[0], y1 = a1[1], w1 = a1[3], x2 = a2[0], y2 = a2[1], w2 = a2[3];
  // Rows of adj(M): the cross products p1 x p2, p2 x p0, p0 x p1 of M's columns p_i = (x_i, y_i, w_i).
  double* n = tri.n;
  n[0] = y1 * w2 - w1 * y2, n[1] = w1 * x2 - x1 * w2, n[2] = x1 * y2 - y1 * x2;
  n[3] = y2 * w0 - w2 * y0, n[4] = w2 * x0 - x2 * w0, n[5] = x2 * y0 - y2 * x0;
  n[6] = y0 * w1 - w0 * y1, n[7] = w0 * x1 - x0 * w1, n[8] = x0 * y1 - y0 * x1;
  if (x0 * n[0] + y0 * n[1] + w0 * n[2] == 0.0) return false;  // det(M) = 0: a line on screen
  for (int i = 0; i < 3; ++i) tri.b[i] = m.clip_b->data() + 4 * size_t{idx[t + i]};
  tri.maps = true;
  return true;
}

// The point of a non-rigid pixel in b's clip space: the pixel centre's perspective-correct
// barycentrics in its triangle of a, applied to b's vertices. With a's vertices (x_i, y_i, w_i) as
// the columns of M, the point sum(l_i c_i) (sum(l_i) = 1) projects to the centre q when
// M l = s (q, 1), s its clip w; so by Cramer's rule l_i is proportional to det(M with column i
// replaced by (q, 1)): one division per pixel for the normalisation instead of one per vertex.
// Inlined: called once per non-rigid pixel. The triangle's own part (adj(M), setTriangle) is kept
// for the pixels after it in the same triangle.
__attribute__((always_inline)) inline std::optional<Eigen::Vector4d> nonRigidClip(DrawMapping& m, uint32_t primitive,
                                                                                double ndc_x, double ndc_y) {
  const DrawMapping::Triangle& tri = m.triangle;
  if (!(tri.cached && tri.primitive == primitive) && !setTriangle(m, primitive)) return std::nullopt;
  if (!tri.maps) return std::nullopt;
  const double* n = tri.n;
  const double l0 = ndc_x * n[0] + ndc_y * n[1] + n[2], l1 = ndc_x * n[3] + ndc_y * n[4] + n[5],
               l2 = ndc_x * n[6] + ndc_y * n[7] + n[8];
  const double sum = l0 + l1 + l2;
  if (sum == 0.0 || !std::isfinite(sum)) return std::nullopt;
  const double inv_sum = 1.0 / sum, k0 = l0 * inv_sum, k1 = l1 * inv_sum, k2 = l2 * inv_sum;
  const float *b0 = tri.b[0], *b1 = tri.b[1], *b2 = tri.b[2];
  return Eigen::Vector4d(k0 * b0[0] + k1 * b1[0] + k2 * b2[0], k0 * b0[1] + k1 * b1[1] + k2 * b2[1],
                         k0 * b0[2] + k1 * b1[2] + k2 * b2[2], k0 * b0[3] + k1 * b1[3] + k2 * b2[3]);
}

// The checks computeFlow and computeSceneFlow (`who`) share: a's pixels and draws, b's draws and
// `buffers` (the caller's other pointers) present, and a's depth in one form. Throws
// std::invalid_argument.
inline void checkFramePixels(const char* who, const FlowFramePixels& a, const FlowFramePixels& b,
                             const std::vector<int32_t>& a_to_b, bool buffers) {
  const size_t n = static_cast<size_t>(a.width) * a.height;
  if (!a.draws || !b.draws || a_to_b.size() != a.draws->size() ||
      (n > 0 && (!buffers || !a.draw_ids || !a.primitive_ids || !(a.depth_window || a.depth_metres))))
    throw std::invalid_argument(std::string(who) + ": an input's size does not match its frame");
  if (a.depth_window && a.depth_metres)
    throw std::invalid_argument(std::string(who) + ": frame a has both window depth and metres");
}

struct Counts {
  // rigid includes behind_rigid: the rigid pixels with a surface whose point is not in front of
  // b's near plane (no flow); non_rigid excludes behind_non_rigid.
  size_t rigid = 0, non_rigid = 0, no_surface = 0, no_assoc = 0, missing = 0, behind_rigid = 0, behind_non_rigid = 0;
};

const float kInfinity = std::numeric_limits<float>::infinity();

// Whether a pixel's depth is a surface: window depth in [0, 1), or metres positive and finite.
inline bool hasSurface(float depth, bool metres) {
  return metres ? depth > 0.0f && depth < kInfinity : depth >= 0.0f && depth < 1.0f;
}

// The window depth of `metres` under rows 2 and 3 of a projection (windowDepthFromMetres'
// arithmetic), or 1 (no surface) where there is none.
inline float windowDepthOf(const DrawMapping& m, float metres) {
  if (!m.has_depth_rows || !(metres > 0.0f) || !(metres < kInfinity)) return 1.0f;
  const double z = -static_cast<double>(metres);
  const double d = 0.5 * ((m.p22 * z + m.p23) / (m.p32 * z + m.p33) + 1.0);
  return d >= 0.0 && d < 1.0 ? static_cast<float>(d) : 1.0f;
}

// One flow computation a -> b over plain pointers: stores through the uint8_t mask may alias
// anything that lives in memory, which would force reloads of state held in vectors.
struct FlowKernel {
  const uint32_t* ids;        // a's draw ids
  const float* depth_a;       // a's window depth, or its metres if `metres`
  bool metres;
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

  // Row y's pointers, for a block kernel to hold in locals: through the uint8_t mask every store
  // could change a member of FlowKernel, so the compiler would reload members after each.
  struct Row {
    const uint32_t* ids;
    const float* depth;
    float* uv;
    uint8_t* visible;
    int32_t *q, *pending;
    float* limit;
    DrawMapping* maps;
    uint32_t last_id;
    DrawMapping& mappingOf(uint32_t id) const { return maps[id <= last_id ? id : 0]; }
  };
  Row rowAt(int y) const {
    const size_t row = static_cast<size_t>(y) * width;
    return {ids + row, depth_a + row, uv + 2 * row, visible + row, row_q, row_pending, row_limit, maps, n_draws};
  }

  // What rigidFrom made of a pixel.
  enum RigidResult { kNoSurface, kFlow, kBehind };

  // Writes pixel p = (x, y) of a rigid draw, which must be at row y.
  RigidResult rigidPixel(DrawMapping& m, int x, int y, size_t p) const {
    const float d = depth_a[p];
    const bool surface = hasSurface(d, metres);
    ++(surface ? m.with_depth : m.without_depth);
    return metres ? rigidFrom<true>(m, x, y, p, d, surface) : rigidFrom<false>(m, x, y, p, 1.0f - d, surface);
  }

  // The same from g: e = 1 - window depth with forms in e, or metres with forms in 1 / metres
  // (kMetres).
  template <bool kMetres>
  RigidResult rigidFrom(const DrawMapping& m, int x, int y, size_t p, float g, bool surface) const {
    const RowForms& f = m.at_row;
    const float xf = static_cast<float>(x);
    float u_cw, v_cw, cw, co;
    if (kMetres) {
      u_cw = ((f.u2 * xf + f.u1) * xf + f.u0) * g + (f.ue1 * xf + f.ue0);
      v_cw = (f.vx * xf + f.v0) * g + f.ve;
      cw = (f.wx * xf + f.w0) * g + f.we, co = (f.ox * xf + f.o0) * g + f.oe;
    } else {
      u_cw = (f.u2 * xf + f.u1) * xf + f.u0 + (f.ue1 * xf + f.ue0) * g;
      v_cw = f.vx * xf + (f.ve * g + f.v0);
      cw = f.wx * xf + (f.we * g + f.w0), co = f.ox * xf + (f.oe * g + f.o0);
    }
    const float r = 1.0f / (cw * co);
    const float inv_cw = co * r, depth = cw * (cw * r);
    const float u = u_cw * inv_cw, v = v_cw * inv_cw;
    const float xb = u + xf, yb = v + static_cast<float>(y);
    const bool front = depth > m.near_b, flow = surface && front;
    bool seen = false;
    if (front && xb >= -0.5f && yb >= -0.5f && xb < width - 0.5f && yb < height - 0.5f) {
      const size_t q = static_cast<size_t>(yb + 0.5f) * width + static_cast<size_t>(xb + 0.5f);
      // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
      seen = !(depth_b[q] < depth * occ_rel - occ_abs);
    }
    uv[2 * p] = flow ? u : kNaN;
    uv[2 * p + 1] = flow ? v : kNaN;
    visible[p] = flow && seen ? 255 : 0;
    return flow ? kFlow : surface ? kBehind : kNoSurface;
  }

  // Counts a rigid pixel as rigidFrom left it (see Counts).
  static void countRigid(RigidResult r, Counts& n) {
    ++(r == kNoSurface ? n.no_surface : n.rigid);
    n.behind_rigid += r == kBehind;
  }

  // Whether a point at (xb, yb) in b's pixel coordinates and `depth` metres in front of b's camera
  // (beyond its near plane) is inside b and not behind b's depth there.
  uint8_t visibleAt(double xb, double yb, double depth) const {
    if (!(xb >= -0.5 && yb >= -0.5 && xb < width - 0.5 && yb < height - 0.5)) return 0;
    const size_t q = static_cast<size_t>(yb + 0.5) * width + static_cast<size_t>(xb + 0.5);
    return !(depth_b[q] < depth * occ_rel - occ_abs) ? 255 : 0;
  }

  void undefined(size_t p) const {
    uv[2 * p] = uv[2 * p + 1] = kNaN;
    visible[p] = 0;
  }

  // Pixel (x, y) of any draw but a rigid one.
  void otherPixel(DrawMapping& m, int x, int y, double ndc_y, Counts& n) const {
    const size_t p = static_cast<size_t>(y) * width + x;
    if (m.kind == DrawMapping::kNoDraw) {
      ++n.no_surface;
      undefined(p);
      return;
    }
    if (m.kind == DrawMapping::kRigidConverted) {
      const float d = windowDepthOf(m, depth_a[p]);
      const bool surface = d < 1.0f;
      ++(surface ? m.with_depth : m.without_depth);
      m.toRow(y, ndc_y);
      countRigid(rigidFrom<false>(m, x, y, p, 1.0f - d, surface), n);
      return;
    }
    const bool surface = hasSurface(depth_a[p], metres);
    ++(surface ? m.with_depth : m.without_depth);
    if (!surface) {
      ++n.no_surface;
      undefined(p);
    } else if (m.kind != DrawMapping::kNonRigid) {
      ++(m.kind == DrawMapping::kNone ? n.no_assoc : n.missing);
      undefined(p);
    } else if (auto clip_b = nonRigidClip(m, primitives[p], 2.0 * (x + 0.5) / width - 1.0, ndc_y)) {
      if (!(clip_b->w() * m.depth_scale_b > m.near_b)) {
        ++n.behind_non_rigid;
        undefined(p);
        return;
      }
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
        countRigid(rigidPixel(m, x, y, row + x), n);
      } else {
        otherPixel(m, x, y, ndc_y, n);
      }
    }
  }

  // Counts the lanes `bits` of the block at x whose draw is m (the lanes with a surface in
  // surface_bits) and queues its non-rigid lanes in `pending`, to be done one at a time after the
  // row's blocks (finishRow). Rigid lanes the block kernel computes itself.
  static void countLanes(DrawMapping& m, unsigned bits, unsigned surface_bits, int x, int32_t* pending,
                         int& n_pending, Counts& c) {
    const int with_surface = __builtin_popcount(bits & surface_bits), without = __builtin_popcount(bits & ~surface_bits);
    if (m.kind != DrawMapping::kNonRigid && m.kind != DrawMapping::kRigidConverted)
      m.with_depth += with_surface, m.without_depth += without;  // those count in otherPixel
    switch (m.kind) {
      case DrawMapping::kRigid:
        c.rigid += with_surface;
        c.no_surface += without;
        break;
      case DrawMapping::kNonRigid:
      case DrawMapping::kRigidConverted:
        for (unsigned b = bits; b; b &= b - 1) pending[n_pending++] = x + __builtin_ctz(b);
        break;
      case DrawMapping::kNoDraw:
        c.no_surface += with_surface + without;
        break;
      case DrawMapping::kNone:
        c.no_assoc += with_surface;
        c.no_surface += without;
        break;
      case DrawMapping::kMissing:
        c.missing += with_surface;
        c.no_surface += without;
        break;
    }
  }

  // After the blocks of row y: the pixels they queued, one at a time, and the row's counts into n.
  void finishRow(int y, double ndc_y, int n_pending, const Counts& blocks, Counts& n) const {
    const uint32_t* const row_ids = ids + static_cast<size_t>(y) * width;
    Counts others;
    for (int i = 0; i < n_pending; ++i)
      otherPixel(mappingOf(row_ids[row_pending[i]]), row_pending[i], y, ndc_y, others);
    n.rigid += blocks.rigid + others.rigid;
    n.non_rigid += others.non_rigid;
    n.no_surface += blocks.no_surface + others.no_surface;
    n.no_assoc += blocks.no_assoc;
    n.missing += blocks.missing + others.missing;
    n.behind_rigid += blocks.behind_rigid + others.behind_rigid;
    n.behind_non_rigid += others.behind_non_rigid;
  }

#ifdef VIPER_X86
  // Pixels x0.. of row y in blocks of 8 (AVX2 + FMA) or 16 (AVX-512), as far as whole blocks go;
  // each returns where the rest of the row begins. Only for CPUs that have the instructions.
  int avx2Pixels(int y, double ndc_y, int x0, Counts& n) const;
  int avx512Pixels(int y, double ndc_y, int x0, Counts& n) const;
#endif
};

}  // namespace flow_detail
}  // namespace viper
