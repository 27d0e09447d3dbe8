#include "viper/core/flow.h"

#include <Eigen/LU>

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

// How the pixels of one draw of frame a map into frame b.
struct DrawMapping {
  enum Kind { kNone, kRigid, kNonRigid, kMissing } kind = kNone;
  // Rigid: inverse(pvw_a) maps ndc_a to the object point times 1 / clip_w_a (a homogeneous point
  // whose w is not 1), so M = pvw_b * inverse(pvw_a) gives clip_b times that same w; its last row
  // gives the w, which the depth in b must be divided by.
  Eigen::Matrix4d ndc_a_to_clip_b = Eigen::Matrix4d::Identity();
  Eigen::Vector4d ndc_a_to_w = Eigen::Vector4d::UnitW();
  const std::vector<uint32_t>* indices = nullptr;                 // non-rigid
  const std::vector<float>* clip_a = nullptr;
  const std::vector<float>* clip_b = nullptr;
  double depth_scale_b = 1.0;  // clip w -> metres along b's optical axis
};

Eigen::Vector4d clipAt(const std::vector<float>& c, uint32_t vertex) {
  const size_t i = 4 * static_cast<size_t>(vertex);
  return Eigen::Vector4d(c[i], c[i + 1], c[i + 2], c[i + 3]);
}

// The point of a non-rigid pixel in b's clip space: screen-space barycentrics of the pixel
// center in its triangle, made perspective-correct with the vertices' w, applied to b's vertices.
std::optional<Eigen::Vector4d> nonRigidClip(const DrawMapping& m, uint32_t primitive, double ndc_x, double ndc_y) {
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

// What a run of rigid pixels needs of frame b and of the options.
struct RigidTarget {
  const float* depth_b;  // b's depth in metres, NaN = no surface
  int width, height;     // b's size
  float occ_rel, occ_abs;
  float *scratch_u, *scratch_v, *scratch_depth;  // a.width values each
  int* scratch_q;
};

// One run of pixels x0..x1-1 of a rigid draw along row y, where
// clip_b = k + x * step_x + d * step_d. Writes (u, v) and the visibility mask of every pixel of the
// run (NaN and 0 where the source depth shows no surface) and returns how many had a surface.
// Branch-free, with clamped indices for b's depth, so that it vectorises (gather). Built twice and
// chosen at load time: for AVX2/FMA CPUs (x86-64-v3) and for any other.
__attribute__((target_clones("arch=x86-64-v3", "default"))) size_t rigidRun(
    const Eigen::Vector4d& k, const Eigen::Vector4d& step_x, const Eigen::Vector4d& step_d, const Eigen::Vector3d& w_k_x_d,
    double depth_scale,
    const RigidTarget& t, const float* depth_row, int x0, int x1, int y, float* uv_row, uint8_t* visible_row) {
  const double k0 = k[0], k1 = k[1], k3 = k[3];
  const double sx0 = step_x[0], sx1 = step_x[1], sx3 = step_x[3];
  const double sd0 = step_d[0], sd1 = step_d[1], sd3 = step_d[3];
  const double kw = w_k_x_d[0], sxw = w_k_x_d[1], sdw = w_k_x_d[2];
  const double half_w = 0.5 * t.width, half_h = 0.5 * t.height;
  const double x_off = 0.5 * t.width - 0.5, y_off = 0.5 * t.height - 0.5 - y;
  const float xmax = t.width - 0.5f, ymax = t.height - 0.5f;
  const float* const depth_b = t.depth_b;
  const int width = t.width, last_x = t.width - 1, last_y = t.height - 1;
  // Four simple loops instead of one: each vectorises on its own (GCC will not if-convert the
  // fused loop). The scratch rows are indexed by x.
  float* const us = t.scratch_u;
  float* const vs = t.scratch_v;
  float* const depths = t.scratch_depth;
  for (int x = x0; x < x1; ++x) {
    const double d = depth_row[x];
    const double cw = k3 + sx3 * x + sd3 * d;
    const double inv = 1.0 / cw;
    us[x] = static_cast<float>((k0 + sx0 * x + sd0 * d) * inv * half_w + (x_off - x));
    vs[x] = static_cast<float>(y_off - (k1 + sx1 * x + sd1 * d) * inv * half_h);
    depths[x] = static_cast<float>(cw / (kw + sxw * x + sdw * d) * depth_scale);
  }
  int* const qs = t.scratch_q;
  const float last_xf = static_cast<float>(last_x), last_yf = static_cast<float>(last_y);
  for (int x = x0; x < x1; ++x) {
    const float xb = us[x] + static_cast<float>(x), yb = vs[x] + static_cast<float>(y), depth = depths[x];
    const bool outside = !(depth > 0.0f) | !(xb >= -0.5f) | !(yb >= -0.5f) | !(xb < xmax) | !(yb < ymax);
    const int xi = static_cast<int>(std::min(std::max(xb + 0.5f, 0.0f), last_xf));
    const int yi = static_cast<int>(std::min(std::max(yb + 0.5f, 0.0f), last_yf));
    qs[x] = (yi * width + xi) | -static_cast<int>(outside);
  }
  for (int x = x0; x < x1; ++x) {
    const int q = qs[x];
    // NaN in b's depth (no surface) counts as visible: nothing is in front of the point.
    const float limit = depths[x] * t.occ_rel - t.occ_abs;
    qs[x] = ((q >= 0) & !(depth_b[std::max(q, 0)] < limit)) ? 255 : 0;
  }
  int valid_count = 0;
  for (int x = x0; x < x1; ++x) {
    const float d = depth_row[x];
    const int surface = (d >= 0.0f) & (d < 1.0f);
    // Adding NaN where there is no surface keeps the loop free of branches.
    const float invalid = surface ? 0.0f : kNaN;
    uv_row[2 * x] = us[x] + invalid;
    uv_row[2 * x + 1] = vs[x] + invalid;
    visible_row[x] = static_cast<uint8_t>(qs[x] & -surface);
    valid_count += surface;
  }
  return valid_count;
}

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

  std::vector<DrawMapping> maps(a.draws.size());
  for (size_t i = 0; i < a.draws.size(); ++i) {
    DrawMapping& m = maps[i];
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
      m.ndc_a_to_clip_b = pvw_b * ndc_a_to_object;
      m.ndc_a_to_w = ndc_a_to_object.row(3).transpose();
    }
  }

  f.width = a.width;
  f.height = a.height;
  f.uv.resize(2 * n);
  f.visible.resize(n);
  const double w = a.width, h = a.height;
  const uint32_t n_draws = static_cast<uint32_t>(maps.size());
  const int width = static_cast<int>(a.width);
  // Plain pointers and local counters: stores through the uint8_t mask may alias anything that
  // lives in memory, which would force reloads of captured state on every pixel.
  float* const uv = f.uv.data();
  uint8_t* const visible = f.visible.data();
  const float* const depth_b = b_depth_m.data();
  const uint32_t* const ids = a.draw_ids.data();
  const float* const depth_a = a.depth_window.data();
  const double bw = b.width, bh = b.height;
  const double occ_rel = 1.0 - options.occlusion_relative, occ_abs = options.occlusion_absolute_m;
  size_t n_rigid = 0, n_non_rigid = 0, n_no_surface = 0, n_no_assoc = 0, n_missing = 0;
  std::vector<float> scratch(3 * static_cast<size_t>(a.width));
  std::vector<int> scratch_q(a.width);
  const RigidTarget target{depth_b,
                           static_cast<int>(b.width),
                           static_cast<int>(b.height),
                           static_cast<float>(occ_rel),
                           static_cast<float>(occ_abs),
                           scratch.data(),
                           scratch.data() + a.width,
                           scratch.data() + 2 * a.width,
                           scratch_q.data()};

  // Whether a point at (xb, yb) in b's pixel coordinates and `depth` metres in front of b's camera
  // is inside b and not behind b's depth there. NaN in b's depth (no surface) counts as visible:
  // nothing is in front of the point.
  auto visibleAt = [depth_b, bw, bh, occ_rel, occ_abs, b_width = static_cast<size_t>(b.width)](
                       double xb, double yb, double depth) -> uint8_t {
    if (!(depth > 0.0 && xb >= -0.5 && yb >= -0.5 && xb < bw - 0.5 && yb < bh - 0.5)) return 0;
    const size_t q = static_cast<size_t>(yb + 0.5) * b_width + static_cast<size_t>(xb + 0.5);
    return !(depth_b[q] < depth * occ_rel - occ_abs) ? 255 : 0;
  };
  auto emit = [uv, visible, w, h, &visibleAt](size_t p, int x, int y, const Eigen::Vector4d& clip_b, double depth_scale) {
    const double inv_w = 1.0 / clip_b.w();
    const double xb = (clip_b.x() * inv_w + 1.0) * 0.5 * w - 0.5;
    const double yb = (1.0 - clip_b.y() * inv_w) * 0.5 * h - 0.5;
    uv[2 * p] = static_cast<float>(xb - x);
    uv[2 * p + 1] = static_cast<float>(yb - y);
    visible[p] = visibleAt(xb, yb, clip_b.w() * depth_scale);
  };
  auto undefined = [uv, visible](size_t p) {
    uv[2 * p] = uv[2 * p + 1] = kNaN;
    visible[p] = 0;
  };

  for (int y = 0; y < static_cast<int>(a.height); ++y) {
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / h;
    const size_t row = static_cast<size_t>(y) * width;
    for (int x0 = 0; x0 < width;) {
      // A run of pixels of one draw along the row shares its mapping.
      const uint32_t id = ids[row + x0];
      int x1 = x0 + 1;
      while (x1 < width && ids[row + x1] == id) ++x1;
      const DrawMapping* m = (id == 0 || id > n_draws) ? nullptr : &maps[id - 1];
      if (m && m->kind == DrawMapping::kRigid) {
        // clip_b = M (ndc_x, ndc_y, 2d - 1, 1) = k + x * step_x + d * step_d. Pass 1 is branch-free
        // so that it vectorises: target pixel and depth for the whole run; pass 2 checks the
        // source depth and looks up b's depth at the target.
        const Eigen::Matrix4d& M = m->ndc_a_to_clip_b;
        const Eigen::Vector4d k = M.col(0) * (1.0 / w - 1.0) + M.col(1) * ndc_y - M.col(2) + M.col(3);
        const Eigen::Vector4d step_x = M.col(0) * (2.0 / w), step_d = M.col(2) * 2.0;
        const Eigen::Vector4d& N = m->ndc_a_to_w;
        const Eigen::Vector3d w_k_x_d(N[0] * (1.0 / w - 1.0) + N[1] * ndc_y - N[2] + N[3], N[0] * (2.0 / w), N[2] * 2.0);
        const size_t with_surface = rigidRun(k, step_x, step_d, w_k_x_d, m->depth_scale_b, target, depth_a + row, x0, x1,
                                             y, uv + 2 * row, visible + row);
        n_rigid += with_surface;
        n_no_surface += (x1 - x0) - with_surface;
      } else {
        for (int x = x0; x < x1; ++x) {
          const size_t p = row + x;
          const float d = depth_a[p];
          if (!m || !(d >= 0.0f && d < 1.0f)) {
            ++n_no_surface;
            undefined(p);
          } else if (m->kind != DrawMapping::kNonRigid) {
            ++(m->kind == DrawMapping::kNone ? n_no_assoc : n_missing);
            undefined(p);
          } else if (auto clip_b = nonRigidClip(*m, a.primitive_ids[p], 2.0 * (x + 0.5) / w - 1.0, ndc_y)) {
            emit(p, x, y, *clip_b, m->depth_scale_b);
            ++n_non_rigid;
          } else {
            ++n_missing;
            undefined(p);
          }
        }
      }
      x0 = x1;
    }
  }
  FlowStats stats;
  stats.rigid = n_rigid, stats.non_rigid = n_non_rigid, stats.no_surface = n_no_surface;
  stats.no_association = n_no_assoc, stats.missing_geometry = n_missing;
  if (stats_out) *stats_out = stats;
}

}  // namespace viper
