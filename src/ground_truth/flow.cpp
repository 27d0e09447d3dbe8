#include "viper/ground_truth/flow.h"

#include "flow_kernel.h"

#include <Eigen/LU>

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace viper {
namespace {

using flow_detail::Counts;
using flow_detail::DrawMapping;
using flow_detail::FlowKernel;

using WorldBytes = std::array<float, 16>;
WorldBytes worldBytes(const DrawRecord& d) {
  WorldBytes w;
  std::memcpy(w.data(), d.world.data(), sizeof(w));
  return w;
}

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

// a's depth in metres m: re-expresses m's forms in s = 1 / m where window depth is affine in s, that
// is where the projection `p` that turned window depth into metres has P33 = 0 (every perspective
// projection): z_ndc = P22 / P32 - P23 / (P32 m), so e = 1 - window depth = alpha + beta s. Returns
// false (forms unchanged) where it is not.
bool setMetresForms(DrawMapping& m, const GlMatrix& p) {
  const double p22 = p(2, 2), p23 = p(2, 3), p32 = p(3, 2), p33 = p(3, 3);
  if (p33 != 0.0 || p32 == 0.0 || !std::isfinite(p22) || !std::isfinite(p23) || !std::isfinite(p32)) return false;
  const double alpha = 0.5 - 0.5 * p22 / p32, beta = 0.5 * p23 / p32;
  if (!std::isfinite(alpha) || !std::isfinite(beta)) return false;
  for (int f = 0; f < 4; ++f) {
    m.form_c[f] += alpha * m.form_e[f];
    m.form_e[f] *= beta;
  }
  return true;
}

// A rigid draw of a whose depth comes in metres under `p` (null: none) that setMetresForms cannot
// take: its pixels are turned into window depth one at a time.
void convertEachPixel(DrawMapping& m, const GlMatrix* p) {
  m.kind = DrawMapping::kRigidConverted;
  m.has_depth_rows = p != nullptr;
  if (p) m.p22 = (*p)(2, 2), m.p23 = (*p)(2, 3), m.p32 = (*p)(3, 2), m.p33 = (*p)(3, 3);
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

namespace {

void checkSameSize(uint32_t a_width, uint32_t a_height, uint32_t b_width, uint32_t b_height) {
  if (a_width != b_width || a_height != b_height)
    throw std::invalid_argument("computeFlow: frame sizes differ (" + std::to_string(a_width) + "x" +
                                std::to_string(a_height) + " vs " + std::to_string(b_width) + "x" +
                                std::to_string(b_height) + ")");
}

// The depth in b (clip w times depth_scale) of the near plane of `projection` (clip z = -w, where
// eye z = -(p23 + p33) / (p22 + p32)), at least 0: the camera plane where a projection defines no
// near plane in front of the camera (a reversed one, say).
float nearPlaneDepth(const GlMatrix& projection, double depth_scale) {
  const double p22 = projection(2, 2), p23 = projection(2, 3), p32 = projection(3, 2), p33 = projection(3, 3);
  if (p22 + p32 == 0.0) return 0.0f;
  const double eye_z = -(p23 + p33) / (p22 + p32);
  const double near = (p32 * eye_z + p33) * depth_scale;
  return std::isfinite(near) && near > 0.0 ? static_cast<float>(near) : 0.0f;
}

}  // namespace

FlowFramePixels flowFramePixels(const CaptureFrame& frame) {
  const size_t n = frame.pixelCount();
  if (frame.draw_ids.size() != n || frame.primitive_ids.size() != n || frame.depth_window.size() != n)
    throw std::invalid_argument("computeFlow: an input's size does not match its frame");
  return {frame.width, frame.height, &frame.draws, frame.draw_ids.data(), frame.primitive_ids.data(),
          frame.depth_window.data()};
}

void computeFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                 const std::vector<float>& b_depth_m, const MeshRegistry& meshes, FlowField& f,
                 const FlowOptions& options, FlowStats* stats_out) {
  checkSameSize(a.width, a.height, b.width, b.height);
  if (a_to_b.size() != a.draws.size() || b_depth_m.size() != a.pixelCount())
    throw std::invalid_argument("computeFlow: an input's size does not match its frame");
  const FlowFramePixels pa = flowFramePixels(a), pb{b.width, b.height, &b.draws};
  f.width = a.width;
  f.height = a.height;
  f.uv.resize(2 * a.pixelCount());
  f.visible.resize(a.pixelCount());
  computeFlow(pa, pb, a_to_b, b_depth_m.data(), meshes, f.uv.data(), f.visible.data(), options, stats_out);
}

void computeFlow(const FlowFramePixels& a, const FlowFramePixels& b, const std::vector<int32_t>& a_to_b,
                 const float* b_depth_m, const MeshRegistry& meshes, float* uv, uint8_t* visible,
                 const FlowOptions& options, FlowStats* stats_out) {
  checkSameSize(a.width, a.height, b.width, b.height);
  const size_t n = static_cast<size_t>(a.width) * a.height;
  flow_detail::checkFramePixels("computeFlow", a, b, a_to_b, b_depth_m && uv && visible);
  const bool metres = a.depth_metres != nullptr;
  const std::vector<DrawRecord>& a_draws = *a.draws;
  const std::vector<DrawRecord>& b_draws = *b.draws;

  // By draw id: maps[0] stands for pixels of no draw.
  std::vector<DrawMapping> maps(a_draws.size() + 1);
  maps[0].kind = DrawMapping::kNoDraw;
  for (size_t i = 0; i < a_draws.size(); ++i) {
    DrawMapping& m = maps[i + 1];
    if (a_to_b[i] < 0 || static_cast<size_t>(a_to_b[i]) >= b_draws.size()) continue;
    const DrawRecord& da = a_draws[i];
    const DrawRecord& db = b_draws[a_to_b[i]];
    m.kind = DrawMapping::kMissing;
    if (db.projection(3, 2) == 0.0f) continue;
    m.depth_scale_b = -1.0 / db.projection(3, 2);
    m.near_b = nearPlaneDepth(db.projection, m.depth_scale_b);
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
      if (metres) {
        // The projection that turned a's window depth into metres (windowDepthFromMetres' choice).
        const GlMatrix* p = (da.matrix_flags & kHasProjection) ? &da.projection : a.depth_projection;
        if (!p || !setMetresForms(m, *p)) convertEachPixel(m, p);
      }
    }
  }

  std::vector<int32_t> row_q(a.width), row_pending(a.width);
  std::vector<float> row_limit(a.width);
  const FlowKernel kernel{a.draw_ids,
                          metres ? a.depth_metres : a.depth_window,
                          metres,
                          a.primitive_ids,
                          b_depth_m,
                          static_cast<int>(a.width),
                          static_cast<int>(a.height),
                          static_cast<float>(1.0 - options.occlusion_relative),
                          static_cast<float>(options.occlusion_absolute_m),
                          maps.data(),
                          static_cast<uint32_t>(a_draws.size()),
                          uv,
                          visible,
                          row_q.data(),
                          row_limit.data(),
                          row_pending.data()};
  // The block kernels look b's depth up in windows of 16 and 32 pixels.
  FlowInstructions path = flowInstructionsUsed(options.instructions);
  if (path == FlowInstructions::kAvx512 && n < 32) path = FlowInstructions::kAvx2;
  if (n < 16) path = FlowInstructions::kScalar;
  Counts counts;
  for (int y = 0; y < static_cast<int>(a.height); ++y) {
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / a.height;
    int x = 0;
#ifdef VIPER_X86
    if (path == FlowInstructions::kAvx512) x = kernel.avx512Pixels(y, ndc_y, x, counts);
    if (path != FlowInstructions::kScalar) x = kernel.avx2Pixels(y, ndc_y, x, counts);
#endif
    kernel.scalarPixels(y, ndc_y, x, kernel.width, counts);
  }
  FlowStats stats;
  stats.rigid = counts.rigid - counts.behind_rigid, stats.non_rigid = counts.non_rigid;
  stats.no_surface = counts.no_surface, stats.behind_b = counts.behind_rigid + counts.behind_non_rigid;
  stats.no_association = counts.no_assoc, stats.missing_geometry = counts.missing;
  for (size_t id = 1; id < maps.size(); ++id)
    if (maps[id].with_depth > 0) stats.no_depth += maps[id].without_depth;
  if (stats_out) *stats_out = stats;
}

}  // namespace viper
