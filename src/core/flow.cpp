#include "viper/core/flow.h"

#include <Eigen/LU>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
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
  Eigen::Matrix4d ndc_a_to_clip_b = Eigen::Matrix4d::Identity();  // rigid
  const std::vector<uint32_t>* indices = nullptr;                 // non-rigid
  const std::vector<float>* clip_a = nullptr;
  const std::vector<float>* clip_b = nullptr;
  double depth_scale_b = 1.0;  // clip w -> metres along b's optical axis
};

Eigen::Vector4d clipAt(const std::vector<float>& c, uint32_t vertex) {
  const size_t i = 4 * static_cast<size_t>(vertex);
  return Eigen::Vector4d(c[i], c[i + 1], c[i + 2], c[i + 3]);
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
                      const std::vector<float>& b_depth_m, const MeshStore& meshes, const FlowOptions& options,
                      FlowStats* stats_out) {
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
      m.ndc_a_to_clip_b = pvw_b * lu.inverse();
    }
  }

  FlowField f;
  f.width = a.width;
  f.height = a.height;
  f.uv.assign(2 * n, kNaN);
  f.visible.assign(n, 0);
  FlowStats stats;
  const double w = a.width, h = a.height;
  const uint32_t n_draws = static_cast<uint32_t>(maps.size());
  for (uint32_t y = 0; y < a.height; ++y) {
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / h;
    for (uint32_t x = 0; x < a.width; ++x) {
      const size_t p = static_cast<size_t>(y) * a.width + x;
      const uint32_t id = a.draw_ids[p];
      const float d = a.depth_window[p];
      if (id == 0 || id > n_draws || !(d >= 0.0f && d < 1.0f)) {
        ++stats.no_surface;
        continue;
      }
      const DrawMapping& m = maps[id - 1];
      const double ndc_x = 2.0 * (x + 0.5) / w - 1.0;
      Eigen::Vector4d clip_b;
      if (m.kind == DrawMapping::kRigid) {
        clip_b = m.ndc_a_to_clip_b * Eigen::Vector4d(ndc_x, ndc_y, 2.0 * d - 1.0, 1.0);
        ++stats.rigid;
      } else if (m.kind == DrawMapping::kNonRigid) {
        const size_t t = 3 * static_cast<size_t>(a.primitive_ids[p]);
        const auto& idx = *m.indices;
        const size_t verts = m.clip_a->size() / 4;
        if (t + 2 >= idx.size() || idx[t] >= verts || idx[t + 1] >= verts || idx[t + 2] >= verts) {
          ++stats.missing_geometry;
          continue;
        }
        const Eigen::Vector4d c0 = clipAt(*m.clip_a, idx[t]), c1 = clipAt(*m.clip_a, idx[t + 1]),
                              c2 = clipAt(*m.clip_a, idx[t + 2]);
        // Screen-space barycentrics of the pixel center, then perspective-correct ones.
        const Eigen::Vector2d s0 = c0.head<2>() / c0.w(), s1 = c1.head<2>() / c1.w(), s2 = c2.head<2>() / c2.w();
        const Eigen::Vector2d q(ndc_x, ndc_y);
        const double area = (s1 - s0).x() * (s2 - s0).y() - (s1 - s0).y() * (s2 - s0).x();
        if (area == 0.0) {
          ++stats.missing_geometry;
          continue;
        }
        const double l1 = ((q - s0).x() * (s2 - s0).y() - (q - s0).y() * (s2 - s0).x()) / area;
        const double l2 = ((s1 - s0).x() * (q - s0).y() - (s1 - s0).y() * (q - s0).x()) / area;
        const double l0 = 1.0 - l1 - l2;
        const double b0 = l0 / c0.w(), b1 = l1 / c1.w(), b2 = l2 / c2.w(), sum = b0 + b1 + b2;
        clip_b = (b0 * clipAt(*m.clip_b, idx[t]) + b1 * clipAt(*m.clip_b, idx[t + 1]) +
                  b2 * clipAt(*m.clip_b, idx[t + 2])) / sum;
        ++stats.non_rigid;
      } else {
        ++(m.kind == DrawMapping::kNone ? stats.no_association : stats.missing_geometry);
        continue;
      }
      const double xb = (clip_b.x() / clip_b.w() + 1.0) * 0.5 * w - 0.5;
      const double yb = (1.0 - clip_b.y() / clip_b.w()) * 0.5 * h - 0.5;
      f.uv[2 * p] = static_cast<float>(xb - x);
      f.uv[2 * p + 1] = static_cast<float>(yb - y);
      const long xi = std::lround(xb), yi = std::lround(yb);
      if (clip_b.w() <= 0.0 || xi < 0 || yi < 0 || xi >= static_cast<long>(b.width) || yi >= static_cast<long>(b.height))
        continue;
      const double depth = clip_b.w() * m.depth_scale_b;
      const float there = b_depth_m[static_cast<size_t>(yi) * b.width + xi];
      if (!std::isfinite(there) || there >= depth - (options.occlusion_relative * depth + options.occlusion_absolute_m))
        f.visible[p] = 255;
    }
  }
  if (stats_out) *stats_out = stats;
  return f;
}

}  // namespace viper
