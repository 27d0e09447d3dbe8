#include "viper/ground_truth/boxes.h"

#include <algorithm>

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

bool MeshRegistry::holds(uint64_t key, const std::vector<float>& positions_xyz,
                         const std::vector<uint32_t>& indices) const {
  const MeshRecord* mesh = find(key);
  return mesh && mesh->positions_xyz == positions_xyz && mesh->indices == indices;
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

void attachParts(std::vector<FrameObject>& objects, const CaptureFrame& frame, const MeshRegistry& meshes,
                 double margin) {
  constexpr double kPartVolume = 0.2;
  // Each thing object's own bounds (its parts sharing its world matrix) and their volume.
  struct Extent {
    Bounds3 bounds;
    double volume = 0.0;
    Eigen::Matrix4d object_from_world;
  };
  std::vector<Extent> extents(objects.size());
  for (size_t k = 0; k < objects.size(); ++k) {
    const FrameObject& o = objects[k];
    if (!o.is_thing) continue;
    for (uint32_t di : o.draws)
      if (di < frame.draws.size())
        if (const Bounds3* b = meshes.bounds(frame.draws[di].mesh_key)) extents[k].bounds.add(*b);
    if (extents[k].bounds.empty()) continue;
    const Eigen::Vector3d size = extents[k].bounds.max - extents[k].bounds.min;
    const Eigen::Vector3d scale = o.world.topLeftCorner<3, 3>().cast<double>().colwise().norm().transpose();
    extents[k].volume = size.cwiseProduct(scale).prod();
    extents[k].bounds.min -= margin * size, extents[k].bounds.max += margin * size;
    extents[k].object_from_world = o.world.cast<double>().inverse();
  }
  std::vector<int> parent(objects.size(), -1);
  for (size_t c = 0; c < objects.size(); ++c) {
    if (!objects[c].is_thing) continue;
    const Eigen::Vector4d origin = objects[c].world.col(3).cast<double>();
    for (size_t p = 0; p < objects.size(); ++p) {
      // A part is much smaller than what it belongs to (a wheel and its kart): two objects of a
      // size (people walking together, cars side by side) never attach.
      if (p == c || objects[p].class_id != objects[c].class_id || extents[p].bounds.empty() ||
          !(extents[c].volume < kPartVolume * extents[p].volume) || !extents[p].object_from_world.allFinite())
        continue;
      const Eigen::Vector3d x = (extents[p].object_from_world * origin).head<3>();
      const bool inside = (x.array() >= extents[p].bounds.min.array()).all() &&
                          (x.array() <= extents[p].bounds.max.array()).all();
      if (inside && (parent[c] < 0 || extents[p].volume > extents[parent[c]].volume)) parent[c] = static_cast<int>(p);
    }
  }
  // Follow chains (a part of a part) to the root, then move every part's draws into its root.
  auto root = [&](size_t k) {
    size_t r = k;
    for (int steps = 0; parent[r] >= 0 && steps < static_cast<int>(objects.size()); ++steps) r = static_cast<size_t>(parent[r]);
    return r;
  };
  bool merged = false;
  for (size_t c = 0; c < objects.size(); ++c) {
    const size_t r = root(c);
    if (r == c) continue;
    FrameObject& into = objects[r];
    into.draws.insert(into.draws.end(), objects[c].draws.begin(), objects[c].draws.end());
    into.mesh_keys.insert(into.mesh_keys.end(), objects[c].mesh_keys.begin(), objects[c].mesh_keys.end());
    into.texture_keys.insert(into.texture_keys.end(), objects[c].texture_keys.begin(), objects[c].texture_keys.end());
    objects[c].draws.clear();
    merged = true;
  }
  if (!merged) return;
  std::vector<FrameObject> kept;
  for (FrameObject& o : objects) {
    if (o.draws.empty()) continue;
    std::sort(o.draws.begin(), o.draws.end());
    std::sort(o.mesh_keys.begin(), o.mesh_keys.end());
    o.mesh_keys.erase(std::unique(o.mesh_keys.begin(), o.mesh_keys.end()), o.mesh_keys.end());
    std::sort(o.texture_keys.begin(), o.texture_keys.end());
    o.texture_keys.erase(std::unique(o.texture_keys.begin(), o.texture_keys.end()), o.texture_keys.end());
    kept.push_back(std::move(o));
  }
  objects.swap(kept);
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
      if ((d.matrix_flags & kHasWorld) && d.world != object.world) {
        // An attached part (attachParts): its bounds' corners in the object's coordinates.
        const Eigen::Matrix4d to_object = world.inverse() * d.world.cast<double>();
        for (int c = 0; c < 8; ++c)
          bounds.add((to_object * Eigen::Vector3d((c & 1) ? b->max.x() : b->min.x(), (c & 2) ? b->max.y() : b->min.y(),
                                                  (c & 4) ? b->max.z() : b->min.z())
                                      .homogeneous())
                         .head<3>());
      } else {
        bounds.add(*b);
      }
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
