#include "viper/ground_truth/scene_flow.h"

#include "flow_kernel.h"

#include <Eigen/LU>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {
namespace {

using flow_detail::DrawMapping;

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// How a's depth gives the homogeneous NDC point of a rigid pixel.
enum class DepthForm : uint8_t { kWindow, kMetres, kConverted };

// How the surface points of one draw of a are formed in both frames.
struct SceneMapping {
  enum Kind : uint8_t { kNone, kRigid, kNonRigid } kind = kNone;
  // Rigid: a's optical coordinates of the point (homogeneous) from a's homogeneous NDC point, and
  // b's. The two share their last row up to b's view * world being affine, so each is divided by
  // its own. Row-major for the pixel loop: a's (a), b's taken into a's optical frame (b_in_a, whose
  // last row is b's), and b's depth row (b_z).
  Eigen::Matrix4d optical_a, optical_b;
  double a[4][4], b_in_a[4][4], b_z[4];
  DepthForm depth = DepthForm::kWindow;
  double p22 = 0, p23 = 0, p32 = 0, p33 = 0;  // the projection a's metres came from
  double z_scale = 0, z_offset = 0;           // kMetres: z_ndc m = z_scale m + z_offset
  bool has_depth_rows = false;                // kConverted: whether there is one
  // Non-rigid: a's and b's clip coordinates into their optical coordinates (homogeneous), and
  // the triangle lookup the flow kernel uses (its barycentrics).
  Eigen::Matrix4d clip_to_optical_a, clip_to_optical_b;
  DrawMapping triangles;
};

Eigen::Matrix4d opticalFromGl4() {
  Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
  f(1, 1) = f(2, 2) = -1.0;
  return f;
}

// Sets a rigid draw's matrices: false if pvw_a is not invertible or a matrix not finite.
bool setRigid(SceneMapping& s, const DrawRecord& da, const DrawRecord& db) {
  const Eigen::Matrix4d vw_a = da.view.cast<double>() * da.world.cast<double>();
  const Eigen::Matrix4d vw_b = db.view.cast<double>() * db.world.cast<double>();
  const Eigen::Matrix4d pvw_a = da.projection.cast<double>() * vw_a;
  Eigen::FullPivLU<Eigen::Matrix4d> lu(pvw_a);
  if (!pvw_a.allFinite() || !vw_b.allFinite() || !lu.isInvertible()) return false;
  const Eigen::Matrix4d ndc_to_object = lu.inverse();
  s.optical_a = opticalFromGl4() * vw_a * ndc_to_object;
  s.optical_b = opticalFromGl4() * vw_b * ndc_to_object;
  return s.optical_a.allFinite() && s.optical_b.allFinite();
}

// As computeFlow chooses for a's metres (setMetresForms / convertEachPixel): the projection `p`
// (null: none) in which window depth is affine in 1 / metres, or each pixel converted.
void setMetres(SceneMapping& s, const GlMatrix* p) {
  if (p) s.p22 = (*p)(2, 2), s.p23 = (*p)(2, 3), s.p32 = (*p)(3, 2), s.p33 = (*p)(3, 3);
  s.has_depth_rows = p != nullptr;
  const bool affine = p && s.p33 == 0.0 && s.p32 != 0.0 && std::isfinite(s.p22) && std::isfinite(s.p23) &&
                      std::isfinite(s.p32) && std::isfinite(0.5 - 0.5 * s.p22 / s.p32) &&
                      std::isfinite(0.5 * s.p23 / s.p32);
  s.depth = affine ? DepthForm::kMetres : DepthForm::kConverted;
  if (affine) s.z_scale = s.p22 / s.p32, s.z_offset = -s.p23 / s.p32;
}

// Writes (dx, dy, dz, d_depth) from the point in a's and b's optical frames; false if not finite.
bool writePoint(const Eigen::Vector3d& in_a, const Eigen::Vector3d& in_b, const Eigen::Isometry3d& a_from_b,
                float* out) {
  const Eigen::Vector3d d = a_from_b * in_b - in_a;
  const double dd = in_b.z() - in_a.z();
  if (!d.allFinite() || !std::isfinite(dd)) return false;
  out[0] = static_cast<float>(d.x()), out[1] = static_cast<float>(d.y()), out[2] = static_cast<float>(d.z());
  out[3] = static_cast<float>(dd);
  return true;
}

}  // namespace

Eigen::Isometry3d opticalMotion(const GlMatrix& view_a, const GlMatrix& view_b) {
  Eigen::Isometry3d m;
  m.matrix() = opticalFromGl4() * view_a.cast<double>() * view_b.cast<double>().inverse() * opticalFromGl4();
  return m;
}

void computeSceneFlow(const FlowFramePixels& a, const FlowFramePixels& b, const std::vector<int32_t>& a_to_b,
                      const MeshRegistry& meshes, const Eigen::Isometry3d& a_from_b, const float* uv, float* xyzd,
                      SceneFlowStats* stats_out) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument("computeSceneFlow: frame sizes differ");
  flow_detail::checkFramePixels("computeSceneFlow", a, b, a_to_b, uv && xyzd);
  const bool metres = a.depth_metres != nullptr;
  const std::vector<DrawRecord>& a_draws = *a.draws;
  const std::vector<DrawRecord>& b_draws = *b.draws;

  // The draws as computeFlow maps them (flow.cpp): by draw id, 0 = no draw.
  std::vector<SceneMapping> maps(a_draws.size() + 1);
  for (size_t i = 0; i < a_draws.size(); ++i) {
    SceneMapping& s = maps[i + 1];
    if (a_to_b[i] < 0 || static_cast<size_t>(a_to_b[i]) >= b_draws.size()) continue;
    const DrawRecord& da = a_draws[i];
    const DrawRecord& db = b_draws[a_to_b[i]];
    if (db.projection(3, 2) == 0.0f) continue;
    if (!da.deformed_clip_xyzw.empty() || !db.deformed_clip_xyzw.empty()) {
      const MeshRecord* mesh = meshes.find(da.mesh_key);
      const size_t verts = mesh ? mesh->positions_xyz.size() / 3 : 0;
      if (!mesh || da.deformed_clip_xyzw.size() != 4 * verts || db.deformed_clip_xyzw.size() != 4 * verts) continue;
      Eigen::FullPivLU<Eigen::Matrix4d> lu_a(da.projection.cast<double>()), lu_b(db.projection.cast<double>());
      if (!lu_a.isInvertible() || !lu_b.isInvertible()) continue;
      s.kind = SceneMapping::kNonRigid;
      s.clip_to_optical_a = opticalFromGl4() * lu_a.inverse();
      s.clip_to_optical_b = opticalFromGl4() * lu_b.inverse();
      s.triangles.indices = &mesh->indices;
      s.triangles.clip_a = &da.deformed_clip_xyzw;
      s.triangles.clip_b = &db.deformed_clip_xyzw;
    } else if (setRigid(s, da, db)) {
      s.kind = SceneMapping::kRigid;
      const Eigen::Matrix4d b_in_a = a_from_b.matrix() * s.optical_b;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) s.a[r][c] = s.optical_a(r, c), s.b_in_a[r][c] = b_in_a(r, c);
      for (int c = 0; c < 4; ++c) s.b_z[c] = s.optical_b(2, c);
      if (metres) setMetres(s, (da.matrix_flags & kHasProjection) ? &da.projection : a.depth_projection);
    }
  }

  SceneFlowStats stats;
  const double width = a.width, height = a.height;
  for (uint32_t y = 0; y < a.height; ++y) {
    const double ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
    for (uint32_t x = 0; x < a.width; ++x) {
      const size_t p = static_cast<size_t>(y) * a.width + x;
      float* out = xyzd + kSceneFlowChannels * p;
      if (std::isnan(uv[2 * p]) || std::isnan(uv[2 * p + 1])) {
        out[0] = out[1] = out[2] = out[3] = static_cast<float>(kNaN);
        continue;
      }
      const uint32_t id = a.draw_ids[p];
      SceneMapping& s = maps[id <= a_draws.size() ? id : 0];
      const double ndc_x = 2.0 * (x + 0.5) / width - 1.0;
      bool formed = false;
      if (s.kind == SceneMapping::kRigid) {
        double ndc[4] = {ndc_x, ndc_y, 0.0, 1.0};
        if (!metres) {
          ndc[2] = 2.0 * a.depth_window[p] - 1.0;
        } else if (s.depth == DepthForm::kMetres) {
          // Times the metres m: (x m, y m, z_ndc m, m), with z_ndc m = (P22 m - P23) / P32.
          const double m = a.depth_metres[p];
          ndc[0] = ndc_x * m, ndc[1] = ndc_y * m, ndc[2] = s.z_scale * m + s.z_offset, ndc[3] = m;
        } else {
          DrawMapping rows;
          rows.has_depth_rows = s.has_depth_rows, rows.p22 = s.p22, rows.p23 = s.p23, rows.p32 = s.p32,
          rows.p33 = s.p33;
          ndc[2] = 2.0 * flow_detail::windowDepthOf(rows, a.depth_metres[p]) - 1.0;
        }
        double ha[4], hb[4];
        for (int r = 0; r < 4; ++r) {
          ha[r] = s.a[r][0] * ndc[0] + s.a[r][1] * ndc[1] + s.a[r][2] * ndc[2] + s.a[r][3] * ndc[3];
          hb[r] = s.b_in_a[r][0] * ndc[0] + s.b_in_a[r][1] * ndc[1] + s.b_in_a[r][2] * ndc[2] + s.b_in_a[r][3] * ndc[3];
        }
        const double zb = s.b_z[0] * ndc[0] + s.b_z[1] * ndc[1] + s.b_z[2] * ndc[2] + s.b_z[3] * ndc[3];
        const double ia = 1.0 / ha[3], ib = 1.0 / hb[3];
        const double d[4] = {hb[0] * ib - ha[0] * ia, hb[1] * ib - ha[1] * ia, hb[2] * ib - ha[2] * ia,
                             zb * ib - ha[2] * ia};
        formed = std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2]) && std::isfinite(d[3]);
        for (int c = 0; c < 4 && formed; ++c) out[c] = static_cast<float>(d[c]);
      } else if (s.kind == SceneMapping::kNonRigid) {
        DrawMapping& t = s.triangles;
        const uint32_t prim = a.primitive_ids[p];
        if ((t.triangle.cached && t.triangle.primitive == prim) || flow_detail::setTriangle(t, prim)) {
          const DrawMapping::Triangle& tri = t.triangle;
          const double* nn = tri.n;
          const double l0 = ndc_x * nn[0] + ndc_y * nn[1] + nn[2], l1 = ndc_x * nn[3] + ndc_y * nn[4] + nn[5],
                       l2 = ndc_x * nn[6] + ndc_y * nn[7] + nn[8];
          const double sum = l0 + l1 + l2;
          if (tri.maps && sum != 0.0 && std::isfinite(sum)) {
            const double k[3] = {l0 / sum, l1 / sum, l2 / sum};
            Eigen::Vector4d clip_a = Eigen::Vector4d::Zero(), clip_b = Eigen::Vector4d::Zero();
            const size_t first = 3 * static_cast<size_t>(prim);
            for (int i = 0; i < 3; ++i) {
              const float* va = t.clip_a->data() + 4 * size_t{(*t.indices)[first + i]};
              const float* vb = tri.b[i];
              for (int c = 0; c < 4; ++c) clip_a[c] += k[i] * va[c], clip_b[c] += k[i] * vb[c];
            }
            const Eigen::Vector4d ha = s.clip_to_optical_a * clip_a, hb = s.clip_to_optical_b * clip_b;
            formed = writePoint(ha.head<3>() / ha.w(), hb.head<3>() / hb.w(), a_from_b, out);
          }
        }
      }
      if (formed) {
        ++stats.defined;
      } else {
        ++stats.unformed;
        out[0] = out[1] = out[2] = out[3] = static_cast<float>(kNaN);
      }
    }
  }
  if (stats_out) *stats_out = stats;
}

std::vector<float> computeSceneFlow(const CaptureFrame& a, const CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                                   const MeshRegistry& meshes, const Eigen::Isometry3d& a_from_b,
                                   const FlowField& flow, SceneFlowStats* stats) {
  if (flow.uv.size() != 2 * a.pixelCount())
    throw std::invalid_argument("computeSceneFlow: the flow's size does not match frame a");
  const FlowFramePixels pa = flowFramePixels(a), pb{b.width, b.height, &b.draws};
  std::vector<float> out(kSceneFlowChannels * a.pixelCount());
  computeSceneFlow(pa, pb, a_to_b, meshes, a_from_b, flow.uv.data(), out.data(), stats);
  return out;
}

}  // namespace viper
