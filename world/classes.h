// VIPER class ids used by the world (see config/viper_classes.csv).
#pragma once

#include <cstdint>

namespace viper {
namespace world {

/// VIPER class ids (a subset: those the world draws).
enum ClassId : uint8_t {
  kUnlabeled = 0,
  kSky = 2,
  kRoad = 3,
  kSidewalk = 4,
  kTerrain = 6,
  kTree = 7,
  kVegetation = 8,
  kBuilding = 9,
  kInfrastructure = 10,
  kFence = 11,
  kBillboard = 12,
  kTrafficLight = 13,
  kTrafficSign = 14,
  kMobileBarrier = 15,
  kFireHydrant = 16,
  kChair = 17,
  kTrash = 18,
  kTrashCan = 19,
  kPerson = 20,
  kMotorcycle = 23,
  kCar = 24,
  kVan = 25,
  kBus = 26,
  kTruck = 27,
};

/// Lower-case VIPER class name of an id ("unlabeled" for ids the world does not use).
const char* className(uint8_t id);

}  // namespace world
}  // namespace viper
