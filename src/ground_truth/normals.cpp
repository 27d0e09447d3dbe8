#include "viper/ground_truth/normals.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace viper {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();

// How the triangles of one draw reach the camera's OpenGL eye coordinates.
struct DrawNormals {
  enum Kind : uint8_t { kNoDraw, kRigid, kDeformed, kMissingMesh, kMissingDeformed, kDegenerate } kind = kNoDraw;
  const MeshRecord* mesh = nullptr;
  const std::vector<float>* clip = nullptr;  // kDeformed: 4 floats a mesh vertex
  Eigen::Matrix4d to_eye = Eigen::Matrix4d::Identity();  // object (kRigid) or clip (kDeformed) -> eye
  // kDeformed under a perspective projection: the draw's eye point from clip x, y and w alone,
  // eye = from_xyw (x, y, w) + xyw_offset, then to_eye (the camera's eye). Clip z is left out: it
  // is A z + B with |A z| far above |B| at a distance, and recovering z from it in float loses
  // digits (a vertex 10 m away moves ~3e-5 m along its ray: a degree on a centimetre triangle).
  // kRigid with an affine to_eye (last row 0 0 0 1, as world and view matrices are): the normal is
  // the cofactor matrix of its linear part L times the object-space normal, (L a) x (L b) =
  // cof(L) (a x b), with the optical frame's axes folded in: one product per triangle, no vertex
  // transformed.
  bool affine = false;
  Eigen::Matrix3d optical_cofactor = Eigen::Matrix3d::Identity();
  bool from_xyw_only = false;
  Eigen::Matrix3d from_xyw = Eigen::Matrix3d::Identity();
  Eigen::Vector3d xyw_offset = Eigen::Vector3d::Zero();
};

// The last triangle looked up: pixels of one triangle mostly follow each other along a row.
struct TriangleCache {
  uint32_t id = 0, primitive = 0;
  bool valid = false;
  enum Result : uint8_t { kOk, kBadPrimitive, kDegenerate } result = kOk;
  float n[3] = {0, 0, 0};  // unit, optical frame, not yet turned towards the camera
};

Eigen::Vector3d eyePoint(const Eigen::Matrix4d& m, double x, double y, double z, double w) {
  const Eigen::Vector4d h = m * Eigen::Vector4d(x, y, z, w);
  return h.head<3>() / h.w();
}

// The normal (not normalised) of the triangle of vertices idx[0..2] in the camera's OpenGL eye frame,
// each vertex taken there.
Eigen::Vector3d eyeNormal(const DrawNormals& d, const uint32_t* idx) {
  Eigen::Vector3d e[3];
  for (int k = 0; k < 3; ++k) {
    const size_t v = idx[k];
    if (d.kind == DrawNormals::kRigid) {
      const float* p = d.mesh->positions_xyz.data() + 3 * v;
      e[k] = eyePoint(d.to_eye, p[0], p[1], p[2], 1.0);
    } else if (d.from_xyw_only) {
      const float* c = d.clip->data() + 4 * v;
      const Eigen::Vector3d eye = d.from_xyw * Eigen::Vector3d(c[0], c[1], c[3]) + d.xyw_offset;
      e[k] = eyePoint(d.to_eye, eye.x(), eye.y(), eye.z(), 1.0);
    } else {
      const float* c = d.clip->data() + 4 * v;
      e[k] = eyePoint(d.to_eye, c[0], c[1], c[2], c[3]);
    }
  }
  return (e[1] - e[0]).cross(e[2] - e[0]);
}

TriangleCache::Result triangleNormal(const DrawNormals& d, uint32_t primitive, float n[3]) {
  const std::vector<uint32_t>& idx = d.mesh->indices;
  const size_t t = 3 * static_cast<size_t>(primitive);
  const size_t verts = d.mesh->positions_xyz.size() / 3;
  if (t + 2 >= idx.size() || idx[t] >= verts || idx[t + 1] >= verts || idx[t + 2] >= verts)
    return TriangleCache::kBadPrimitive;
  Eigen::Vector3d normal;
  if (d.affine) {
    const float* p[3];
    for (int k = 0; k < 3; ++k) p[k] = d.mesh->positions_xyz.data() + 3 * size_t{idx[t + k]};
    const Eigen::Vector3d a(double(p[1][0]) - p[0][0], double(p[1][1]) - p[0][1], double(p[1][2]) - p[0][2]);
    const Eigen::Vector3d b(double(p[2][0]) - p[0][0], double(p[2][1]) - p[0][1], double(p[2][2]) - p[0][2]);
    normal = d.optical_cofactor * a.cross(b);
  } else {
    normal = eyeNormal(d, idx.data() + t);
    // OpenGL eye axes (x right, y up, z backwards) to optical (x right, y down, z forward).
    normal.y() = -normal.y(), normal.z() = -normal.z();
  }
  const double length = normal.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return TriangleCache::kDegenerate;
  for (int k = 0; k < 3; ++k) n[k] = static_cast<float>(normal[k] / length);
  return TriangleCache::kOk;
}

std::vector<DrawNormals> drawNormals(const std::vector<DrawRecord>& draws, const FrameCamera& camera,
                                     const MeshRegistry& meshes) {
  std::vector<DrawNormals> out(draws.size() + 1);  // by draw id; out[0] stands for no draw
  const Eigen::Matrix4d camera_view = camera.view.cast<double>();
  for (size_t i = 0; i < draws.size(); ++i) {
    const DrawRecord& draw = draws[i];
    DrawNormals& d = out[i + 1];
    d.mesh = meshes.find(draw.mesh_key);
    if (!d.mesh) {
      d.kind = DrawNormals::kMissingMesh;
      continue;
    }
    // A draw with a view of its own is placed in the world by its world matrix: the camera's view
    // takes it to the frame's eye. Without one, its world matrix is the program's model-view.
    const bool has_view = (draw.matrix_flags & kHasView) != 0;
    const Eigen::Matrix4d world = draw.world.cast<double>();
    if (draw.deformed_clip_xyzw.empty()) {
      d.kind = DrawNormals::kRigid;
      d.to_eye = has_view ? Eigen::Matrix4d(camera_view * world) : world;
      d.affine = d.to_eye.row(3) == Eigen::RowVector4d(0, 0, 0, 1);
      if (d.affine) {
        const Eigen::Matrix3d l = d.to_eye.topLeftCorner<3, 3>();
        Eigen::Matrix3d cofactor;
        cofactor.row(0) = l.row(1).cross(l.row(2));
        cofactor.row(1) = l.row(2).cross(l.row(0));
        cofactor.row(2) = l.row(0).cross(l.row(1));
        d.optical_cofactor = Eigen::Vector3d(1, -1, -1).asDiagonal() * cofactor;
      }
    } else if (draw.deformed_clip_xyzw.size() != 4 * (d.mesh->positions_xyz.size() / 3)) {
      d.kind = DrawNormals::kMissingDeformed;
      continue;
    } else {
      d.kind = DrawNormals::kDeformed;
      d.clip = &draw.deformed_clip_xyzw;
      const GlMatrix& projection = (draw.matrix_flags & kHasProjection) ? draw.projection : camera.projection;
      const Eigen::Matrix4d pd = projection.cast<double>();
      const Eigen::FullPivLU<Eigen::Matrix4d> p(pd);
      const Eigen::FullPivLU<Eigen::Matrix4d> v(draw.view.cast<double>());
      if (!p.isInvertible() || (has_view && !v.isInvertible())) {
        d.kind = DrawNormals::kDegenerate;
        continue;
      }
      const Eigen::Matrix4d correction = has_view ? Eigen::Matrix4d(camera_view * v.inverse())
                                                  : Eigen::Matrix4d(Eigen::Matrix4d::Identity());
      // Rows x, y, w of the projection on the eye point (x, y, z, 1): invertible under a perspective.
      Eigen::Matrix3d xyw;
      Eigen::Vector3d t;
      for (int r = 0; r < 3; ++r) {
        const int row = r == 2 ? 3 : r;
        xyw.row(r) = pd.block<1, 3>(row, 0);
        t[r] = pd(row, 3);
      }
      const Eigen::FullPivLU<Eigen::Matrix3d> m(xyw);
      d.from_xyw_only = pd(3, 2) != 0.0 && m.isInvertible();
      if (d.from_xyw_only) {
        d.from_xyw = m.inverse();
        d.xyw_offset = -d.from_xyw * t;
        d.to_eye = correction;
      } else {
        d.to_eye = correction * p.inverse();
      }
      if (!d.from_xyw.allFinite()) d.kind = DrawNormals::kDegenerate;
    }
    if (!d.to_eye.allFinite()) d.kind = DrawNormals::kDegenerate;
  }
  return out;
}

}  // namespace

PixelRays::PixelRays(const FrameCamera& camera, uint32_t width, uint32_t height) {
  try {
    const PinholeIntrinsics k = intrinsicsFromGlProjection(camera.projection, width, height);
    perspective_ = true;
    cx_ = static_cast<float>(k.cx), cy_ = static_cast<float>(k.cy);
    inv_fx_ = static_cast<float>(1.0 / k.fx), inv_fy_ = static_cast<float>(1.0 / k.fy);
  } catch (const std::invalid_argument&) {
    perspective_ = false;  // orthographic (or unusual): the rays are parallel to the optical axis
  }
}

void computeNormals(const GroundTruthInput& in, const FrameCamera& camera, const MeshRegistry& meshes, float* out,
                    NormalStats* stats_out) {
  const CaptureFrame& f = in.frame;
  const std::vector<DrawNormals> draws = drawNormals(f.draws, camera, meshes);
  const uint32_t n_draws = static_cast<uint32_t>(f.draws.size());
  const PixelRays rays(camera, f.width, f.height);
  NormalStats stats;
  TriangleCache cache;
  // Why a pixel has no normal: the count it goes to, and the first draw of each kind of bad input.
  enum Failure { kNone, kNoSurface, kMissingMesh, kMissingDeformed, kBadPrimitive, kDegenerate };
  auto fail = [&](size_t p, Failure why, uint32_t id) {
    out[3 * p] = out[3 * p + 1] = out[3 * p + 2] = kNaN;
    auto note = [&](size_t& count, long& first) {
      ++count;
      if (first < 0) first = static_cast<long>(id) - 1;
    };
    long unnamed = 0;
    switch (why) {
      case kMissingMesh: note(stats.missing_mesh, stats.first_missing_mesh); break;
      case kMissingDeformed: note(stats.missing_deformed, stats.first_missing_deformed); break;
      case kBadPrimitive: note(stats.bad_primitive, stats.first_bad_primitive); break;
      case kDegenerate: note(stats.degenerate, unnamed); break;
      default: ++stats.no_surface;
    }
  };
  for (uint32_t y = 0; y < f.height; ++y) {
    const float ray_y = rays.y(y);
    for (uint32_t x = 0; x < f.width; ++x) {
      const size_t p = static_cast<size_t>(y) * f.width + x;
      const uint32_t id = in.draw_ids[p];
      const float depth = in.depth_m[p];
      if (id == 0 || id > n_draws || !(depth > 0.0f) || !(depth < std::numeric_limits<float>::infinity())) {
        fail(p, kNoSurface, id);
        continue;
      }
      const DrawNormals& d = draws[id];
      Failure why = d.kind == DrawNormals::kMissingMesh       ? kMissingMesh
                    : d.kind == DrawNormals::kMissingDeformed ? kMissingDeformed
                    : d.kind == DrawNormals::kDegenerate      ? kDegenerate
                                                              : kNone;
      if (why == kNone) {
        const uint32_t primitive = in.primitive_ids[p];
        if (!cache.valid || cache.id != id || cache.primitive != primitive) {
          cache.valid = true, cache.id = id, cache.primitive = primitive;
          cache.result = triangleNormal(d, primitive, cache.n);
        }
        why = cache.result == TriangleCache::kBadPrimitive ? kBadPrimitive
              : cache.result == TriangleCache::kDegenerate ? kDegenerate
                                                           : kNone;
      }
      if (why != kNone) {
        fail(p, why, id);
        continue;
      }
      // Turned towards the camera: against the pixel's viewing ray.
      const float facing = cache.n[0] * rays.x(x) + cache.n[1] * ray_y + cache.n[2];
      const float sign = facing > 0.0f ? -1.0f : 1.0f;
      out[3 * p] = sign * cache.n[0], out[3 * p + 1] = sign * cache.n[1], out[3 * p + 2] = sign * cache.n[2];
      ++stats.with_normal;
    }
  }
  if (stats_out) *stats_out = stats;
}

bool NormalsStep::process(const GroundTruthInput& in, const std::optional<FrameCamera>& camera,
                          const MeshRegistry& meshes, float* out, StepProblems& problems, NormalStats* stats) const {
  const CaptureFrame& f = in.frame;
  const size_t n = f.pixelCount();
  const std::string frame = " (frame " + std::to_string(f.number) + "): ";
  auto none = [&](StepInput input, const char* kind, const std::string& why) {
    std::fill(out, out + 3 * n, kNaN);
    problems.push_back({input, StepSeverity::kError, kind, frame + why + "; no normals for this frame"});
    if (stats) *stats = NormalStats();
    return false;
  };
  if (!in.draw_ids) return none(StepInput::kDrawIds, "no_ids", "no draw ids");
  if (!in.primitive_ids) return none(StepInput::kPrimitiveIds, "no_ids", "no primitive ids");
  if (!in.depth_m) return none(StepInput::kDepth, "no_depth", "no depth");
  if (!camera) return none(StepInput::kDraws, "no_camera", "no draw carries both a view and a projection matrix");
  const uint32_t largest = largestDrawId(in.draw_ids, n);
  if (largest > f.draws.size())
    return none(StepInput::kDrawIds, "draw_ids",
                "draw id " + std::to_string(largest) + " in draw_ids, but only " + std::to_string(f.draws.size()) +
                    " draws");
  NormalStats s;
  computeNormals(in, *camera, meshes, out, &s);
  // "N px <what> (first: draw D, mesh K<detail>); their normals are NaN".
  auto report = [&](size_t count, long first, StepInput input, const char* kind, const char* what,
                    const std::string& detail) {
    if (count == 0) return;
    char text[512];
    std::snprintf(text, sizeof text, "%s%zu px %s (first: draw %ld, mesh %016llx%s); their normals are NaN",
                  frame.c_str(), count, what, first,
                  static_cast<unsigned long long>(f.draws[static_cast<size_t>(first)].mesh_key), detail.c_str());
    problems.push_back({input, StepSeverity::kError, kind, text});
  };
  report(s.missing_mesh, s.first_missing_mesh, StepInput::kMeshStore, "missing_mesh",
         "of draws whose mesh is not in the mesh store", "");
  if (s.missing_deformed > 0) {
    const DrawRecord& d = f.draws[static_cast<size_t>(s.first_missing_deformed)];
    report(s.missing_deformed, s.first_missing_deformed, StepInput::kDraws, "deformed",
           "of deformed draws without their vertex positions",
           ", " + std::to_string(d.deformed_clip_xyzw.size() / 4) + " positions for " +
               std::to_string(meshes.find(d.mesh_key)->positions_xyz.size() / 3) + " vertices");
  }
  report(s.bad_primitive, s.first_bad_primitive, StepInput::kPrimitiveIds, "primitive_ids",
         "with a primitive id past their mesh's triangles", "");
  if (stats) *stats = s;
  return true;
}

}  // namespace viper
