// Oriented 3D boxes of objects from their meshes' vertices (docs/ground_truth.md, "Boxes").
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/objects.h"

#include <Eigen/Geometry>

#include <array>
#include <unordered_map>
#include <vector>

namespace viper {

/// Axis-aligned bounds in some frame; empty until a point is added.
struct Bounds3 {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  bool empty() const { return !(min.array() <= max.array()).all(); }
  void add(const Eigen::Vector3d& p) { min = min.cwiseMin(p), max = max.cwiseMax(p); }
  void add(const Bounds3& b) { min = min.cwiseMin(b.min), max = max.cwiseMax(b.max); }
};

/// Every mesh of a capture, accumulated from the frames' new_meshes, with cached bounds.
class MeshRegistry {
 public:
  /// Adds the frame's new meshes (a key seen before is replaced).
  void add(const std::vector<MeshRecord>& meshes);
  void add(const MeshRecord& mesh);
  /// nullptr if the key never arrived.
  const MeshRecord* find(uint64_t key) const;
  /// Whether it holds `key` with exactly these positions and indices: a mesh store, sent again
  /// whole with every new mesh, need not be added again.
  bool holds(uint64_t key, const std::vector<float>& positions_xyz, const std::vector<uint32_t>& indices) const;
  /// Object-space bounds of a mesh's vertices; nullptr if the key never arrived or it is empty.
  const Bounds3* bounds(uint64_t key) const;
  /// Surface area of a mesh's triangles in its own units (0 for unknown keys).
  double area(uint64_t key) const;
  size_t size() const { return meshes_.size(); }

 private:
  struct Entry {
    MeshRecord mesh;
    Bounds3 bounds;
    double area = 0.0;
  };
  std::unordered_map<uint64_t, Entry> meshes_;
};

/// An oriented box: the object's own axes, its extent along them, in the world (map) frame.
struct OrientedBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();         ///< metres, world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< object axes in the world
  Eigen::Vector3d size = Eigen::Vector3d::Zero();           ///< full extent along the object axes (m)
  /// The 8 corners in the world: bit 0 of the index picks +x, bit 1 +y, bit 2 +z.
  std::array<Eigen::Vector3d, 8> corners() const;
  /// The same box expressed in another frame: `T_frame_world` maps world points into it.
  OrientedBox transformed(const Eigen::Isometry3d& T_frame_world) const;
};

/// Why a box could not be made.
enum class BoxStatus { kOk, kMissingMesh, kSingularMatrix, kEmpty };

/// Parts an engine places under a parent with matrices of their own (a kart's wheels): a thing
/// object whose origin lies inside the box of a thing object of the same class at least five times
/// its volume, in that object's coordinates (its parts' mesh bounds, grown by `margin` of their
/// size on each side), is merged into it (the largest such). Objects come out in the order of their first draw.
void attachParts(std::vector<FrameObject>& objects, const CaptureFrame& frame, const MeshRegistry& meshes,
                 double margin = 0.05);

/// Box of an object: the union of its parts' vertices in the object's coordinates (rigid parts from
/// the mesh store, moved by their own world matrix where it is not the object's; deformed parts from
/// their post-vertex-shader positions mapped back through the inverse of projection * view * world),
/// placed with the object's world matrix. The world
/// matrix's rotation is taken from its polar decomposition, its column norms scale the size.
/// Parts whose mesh never arrived are skipped and reported through `status` (kMissingMesh) when no
/// part is left.
OrientedBox objectBox(const CaptureFrame& frame, const FrameObject& object, const MeshRegistry& meshes,
                      BoxStatus* status = nullptr);

}  // namespace viper
