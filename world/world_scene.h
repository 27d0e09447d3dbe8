// The whole world: town, traffic, people and ego, stepped once per frame and drawn object by
// object (distance and frustum culling, vehicle levels of detail, condition lighting).
#pragma once

#include "ego.h"
#include "mesh_library.h"
#include "options.h"
#include "renderer.h"
#include "town_layout.h"
#include "traffic.h"
#include "vehicles.h"

#include <vector>

namespace viper {
namespace world {

/// Owns the simulation; builds all meshes on construction (no GL needed).
class WorldScene {
 public:
  explicit WorldScene(const Options& options);

  MeshLibrary& meshes() { return meshes_; }
  /// Advances the simulation by one frame (1 / fps seconds).
  void step();
  /// Issues the draw calls of the current frame; fills `oracle` camera fields if non-null.
  void render(Renderer& renderer, OracleFrame* oracle);
  double time() const { return t_; }

 private:
  bool visible(Vec3 center, float radius) const;
  void drawVehicle(Renderer& r, const Vehicle& v);
  void drawPerson(Renderer& r, uint32_t id, int variant, Activity a, float phase, const Mat4& world);
  FrameLighting lighting() const;

  Options options_;
  MeshLibrary meshes_;
  TownLayout town_;
  std::array<VehicleModel, kVehicleKinds> models_;
  std::vector<int> person_meshes_;
  Traffic traffic_;
  Ego ego_;
  ConditionParams cond_;
  Mat4 view_, proj_;
  Vec3 cam_pos_, cam_fwd_;
  float draw_distance_m_ = 180.0f;
  double t_ = 0;
  uint32_t first_dynamic_id_ = 0;
};

}  // namespace world
}  // namespace viper
