// Vehicle models: car, van, bus, truck, motorcycle. Each is a set of part meshes placed in the
// vehicle frame (x forward, y left, z up, origin on the ground under the centre), in two levels of
// detail. Wheels and headlights are shared between car and van, heavy wheels between bus and truck.
#pragma once

#include "mesh_library.h"

#include <array>
#include <cstdint>

namespace viper {
namespace world {

/// Vehicle kinds, in the order of VehicleModels.
enum VehicleKind { kKindCar = 0, kKindVan, kKindBus, kKindTruck, kKindMotorcycle, kVehicleKinds };

/// Part meshes of one vehicle class; each part has a near (lod 0) and a far (lod 1) mesh.
struct VehicleModel {
  uint8_t class_id = 0;
  float length_m = 0, width_m = 0, height_m = 0;
  int body[2] = {-1, -1};
  int windows[2] = {-1, -1};
  int wheels[2] = {-1, -1};
  int headlights[2] = {-1, -1};
  int taillights[2] = {-1, -1};
};

/// Distance (m) beyond which the far level of detail is drawn.
constexpr float kVehicleLodDistance = 35.0f;

/// Registers every vehicle part mesh in `meshes` and returns the five models.
std::array<VehicleModel, kVehicleKinds> buildVehicleModels(MeshLibrary& meshes);

}  // namespace world
}  // namespace viper
