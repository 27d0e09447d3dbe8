// The test scene's content and animation: which objects exist, their parts and meshes, and where
// everything (camera included) is at a given simulated time. Pure math, no OpenGL.
#pragma once

#include "geometry.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace scene {

/// Shader program a draw uses.
enum class ProgramKind { kLit, kSkinned, kRain };

/// Number of bones of the skinned program (size of `uniform mat4 uBones[N]`).
constexpr int kBoneCount = 3;

/// One draw call of a frame, in issue order.
struct DrawItem {
  uint32_t object_id = 0;
  uint32_t class_id = 0;  ///< VIPER class id
  std::string part;
  size_t mesh = 0;  ///< index into World::meshes()
  ProgramKind program = ProgramKind::kLit;
  Eigen::Matrix4f world = Eigen::Matrix4f::Identity();  ///< model -> world (Z up, metres)
  Eigen::Vector3f color = Eigen::Vector3f::Ones();      ///< Lambert albedo (lit and skinned programs)
  std::vector<Eigen::Matrix4f> bones;                   ///< kBoneCount matrices for kSkinned, else empty
};

/// Everything needed to render and describe one frame.
struct FrameState {
  double time_s = 0.0;
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();           ///< world -> OpenGL camera
  Eigen::Matrix4f projection = Eigen::Matrix4f::Identity();     ///< OpenGL perspective
  Eigen::Matrix4d map_from_camera_body = Eigen::Matrix4d::Identity();  ///< REP 103 camera body in world
  std::vector<DrawItem> draws;  ///< opaque draws first, the transparent rain last
};

/// The town block: terrain, road, two buildings sharing one box mesh, a crate, two cars sharing
/// body/cabin/wheel meshes, a skinned person, rain. `seed` varies building heights, car phases and
/// rain streak placement.
class World {
 public:
  World(uint64_t seed, double aspect);

  /// Meshes in upload order; DrawItem::mesh indexes this.
  const std::vector<MeshData>& meshes() const { return meshes_; }

  /// State at simulated time `time_s` (seconds).
  FrameState frame(double time_s) const;

 private:
  size_t addMesh(MeshData mesh);
  void addCar(std::vector<DrawItem>& draws, uint32_t id, const Eigen::Matrix4f& world, const Eigen::Vector3f& color) const;

  double aspect_;
  std::vector<MeshData> meshes_;
  size_t terrain_ = 0, road_ = 0, box_ = 0, crate_ = 0, car_body_ = 0, car_cabin_ = 0, tube_ = 0, rain_ = 0;
  size_t wheels_[4] = {0, 0, 0, 0};
  float building_height_[2] = {10, 14};
  double car_phase_[2] = {0, 0};
};

/// OpenGL perspective matrix (gluPerspective): vertical field of view in radians.
Eigen::Matrix4f perspective(double fovy_rad, double aspect, double near_m, double far_m);

/// View matrix (world -> OpenGL camera: x right, y up, looking down -z) of a camera whose REP 103
/// body frame (x forward, y left, z up) has pose `map_from_body` in the world.
Eigen::Matrix4f viewFromBodyPose(const Eigen::Matrix4d& map_from_body);

}  // namespace scene
}  // namespace viper
