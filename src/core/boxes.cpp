#include "viper/core/boxes.h"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace viper {

void MeshRegistry::add(const std::vector<MeshRecord>& meshes) {
  for (const MeshRecord& m : meshes) add(m);
}

void MeshRegistry::add(const MeshRecord& mesh) {
  Entry e;
  e.mesh = mesh;
  const size_t n = mesh.positions_xyz.size() / 3;
  auto vertex = [&](size_t i) {
    return Eigen::Vector3d(mesh.positions_xyz[3 * i], mesh.positions_xyz[3 * i + 1], mesh.positions_xyz[3 * i + 2]);
  };
  for (size_t i = 0; i < n; ++i) e.bounds.add(vertex(i));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (a >= n || b >= n || c >= n) continue;
    e.area += 0.5 * (vertex(b) - vertex(a)).cross(vertex(c) - vertex(a)).norm();
  }
  meshes_[mesh.key] = std::move(e);
}

const MeshRecord* MeshRegistry::find(uint64_t key) const {
  auto it = meshes_.find(key);
  return it == meshes_.end() ? nullptr : &it->second.mesh;
}

const Bounds3* MeshRegistry::bounds(uint64_t key) const {
  auto it = meshes_.find(key);
  return it == meshes_.end() || it->second.bounds.empty() ? nullptr : &it->second.bounds;
}

double MeshRegistry::area(uint64_t key) const {
  auto it = meshes_.find(key);
  return it == meshes_.end() ? 0.0 : it->second.area;
}

std::array<Eigen::Vector3d, 8> OrientedBox::corners() const {
  std::array<Eigen::Vector3d, 8> c;
  const Eigen::Matrix3d r = orientation.toRotationMatrix();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d s((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    c[i] = center + r * s.cwiseProduct(size);
  }
  return c;
}

OrientedBox OrientedBox::transformed(const Eigen::Isometry3d& T) const {
  OrientedBox b = *this;
  b.center = T * center;
  b.orientation = Eigen::Quaterniond(T.linear()) * orientation;
  b.orientation.normalize();
  return b;
}

OrientedBox objectBox(const CaptureFrame& frame, const FrameObject& object, const MeshRegistry& meshes,
                      BoxStatus* status) {
  const Eigen::Matrix4d world = object.world.cast<double>();
  const Eigen::Matrix3d linear = world.topLeftCorner<3, 3>();
  OrientedBox box;
  auto fail = [&](BoxStatus s) {
    if (status) *status = s;
    return box;
  };
  if (!world.allFinite() || std::abs(linear.determinant()) < 1e-12) return fail(BoxStatus::kSingularMatrix);

  Bounds3 bounds;
  bool missing = false;
  for (uint32_t di : object.draws) {
    if (di >= frame.draws.size()) continue;
    const DrawRecord& d = frame.draws[di];
    if (!d.deformed_clip_xyzw.empty()) {
      const Eigen::Matrix4d clip_to_object =
          (d.projection.cast<double>() * d.view.cast<double>() * world).inverse();
      if (!clip_to_object.allFinite()) continue;
      for (size_t i = 0; i + 3 < d.deformed_clip_xyzw.size(); i += 4) {
        const Eigen::Vector4d clip(d.deformed_clip_xyzw[i], d.deformed_clip_xyzw[i + 1], d.deformed_clip_xyzw[i + 2],
                                   d.deformed_clip_xyzw[i + 3]);
        const Eigen::Vector4d p = clip_to_object * clip;
        if (std::abs(p.w()) > 1e-12) bounds.add(p.head<3>() / p.w());
      }
    } else if (const Bounds3* b = meshes.bounds(d.mesh_key)) {
      bounds.add(*b);
    } else {
      missing = true;
    }
  }
  if (bounds.empty()) return fail(missing ? BoxStatus::kMissingMesh : BoxStatus::kEmpty);

  Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) rotation = -rotation;  // a mirrored object keeps a proper rotation
  const Eigen::Vector3d scale = linear.colwise().norm().transpose();
  box.center = (world * (0.5 * (bounds.min + bounds.max)).homogeneous()).head<3>();
  box.orientation = Eigen::Quaterniond(rotation).normalized();
  box.size = (bounds.max - bounds.min).cwiseProduct(scale);
  if (status) *status = BoxStatus::kOk;
  return box;
}

}  // namespace viper
