// CPU-side triangle meshes and the primitive builders the world is made of (boxes, cylinders,
// extruded profiles, low-poly spheres). Positions are object-space metres, Z up.
#pragma once

#include "math3d.h"

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace world {

/// An indexed triangle mesh with per-vertex normal and color, optionally skinned (4 bones/vertex).
struct MeshData {
  std::vector<float> positions;  ///< xyz per vertex (the buffer bound to aPos)
  std::vector<float> normals;    ///< xyz per vertex
  std::vector<float> colors;     ///< rgb per vertex, linear 0..1
  std::vector<float> bone_ids;   ///< 4 per vertex (as floats), empty when not skinned
  std::vector<float> bone_weights;  ///< 4 per vertex, sum 1, empty when not skinned
  std::vector<uint32_t> indices;

  size_t vertexCount() const { return positions.size() / 3; }
  bool skinned() const { return !bone_ids.empty(); }

  /// Adds one vertex; returns its index. Skinned meshes get `bone` with weight 1.
  uint32_t addVertex(Vec3 p, Vec3 n, Vec3 c);
  /// Bone of every vertex added from now on (skinned meshes only; -1 = not skinned).
  int current_bone = -1;

  /// Axis-aligned box of half extents `half` centred at the origin of `m`.
  void addBox(const Mat4& m, Vec3 half, Vec3 color);
  /// Cylinder along +Z from z=0 to z=height at the origin of `m` (with caps).
  void addCylinder(const Mat4& m, float radius, float height, int segments, Vec3 color,
                   float top_radius = -1.0f);
  /// Low-poly ellipsoid of radii `r` centred at the origin of `m`.
  void addSphere(const Mat4& m, Vec3 r, int segments, int rings, Vec3 color);
  /// A convex polygon given in the x-z plane (counter-clockwise seen from -y), extruded over
  /// y in [-half_width, half_width], transformed by `m`.
  void addExtrusion(const Mat4& m, const std::vector<Vec3>& profile_xz, float half_width,
                    Vec3 color);
  /// A flat quad (two triangles) with corners in order, normal from the winding.
  void addQuad(Vec3 a, Vec3 b, Vec3 c, Vec3 d, Vec3 color);
  /// Appends another mesh transformed by `m`.
  void append(const MeshData& other, const Mat4& m);

  /// Object-space bounding sphere (centre, radius) of the positions.
  void bounds(Vec3& center, float& radius) const;
};

}  // namespace world
}  // namespace viper
