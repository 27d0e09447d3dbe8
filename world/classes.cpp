#include "classes.h"

namespace viper {
namespace world {

const char* className(uint8_t id) {
  switch (id) {
    case kSky: return "sky";
    case kRoad: return "road";
    case kSidewalk: return "sidewalk";
    case kTerrain: return "terrain";
    case kTree: return "tree";
    case kVegetation: return "vegetation";
    case kBuilding: return "building";
    case kInfrastructure: return "infrastructure";
    case kFence: return "fence";
    case kBillboard: return "billboard";
    case kTrafficLight: return "trafficlight";
    case kTrafficSign: return "trafficsign";
    case kMobileBarrier: return "mobilebarrier";
    case kFireHydrant: return "firehydrant";
    case kChair: return "chair";
    case kTrash: return "trash";
    case kTrashCan: return "trashcan";
    case kPerson: return "person";
    case kMotorcycle: return "motorcycle";
    case kCar: return "car";
    case kVan: return "van";
    case kBus: return "bus";
    case kTruck: return "truck";
    default: return "unlabeled";
  }
}

}  // namespace world
}  // namespace viper
