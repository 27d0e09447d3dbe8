// Traffic and pedestrians: vehicles drive in lanes along the town's straight roads, keep their
// distance and stop at red lights; pedestrians walk around blocks on the sidewalks, cross at
// crossings while the cars have red, stand, or sit on chairs. Stepped with a fixed time step;
// all randomness from one seeded std::mt19937.
#pragma once

#include "people.h"
#include "town_layout.h"
#include "vehicles.h"

#include <random>
#include <vector>

namespace viper {
namespace world {

/// A vehicle on a lane: travels along `axis` (0: x, 1: y) on road `line` in direction `dir`.
struct Vehicle {
  uint32_t id = 0;
  int kind = kKindCar;
  int axis = 0, line = 0, dir = 1, lane = 0;  ///< lane 0: inner, 1: outer (right-hand traffic)
  double s = 0;        ///< coordinate along the axis (m)
  double v = 0;        ///< speed (m/s)
  float vmax = 10.0f;  ///< cruising speed (m/s)
  Vec3 tint{1, 1, 1};
  uint32_t rider_id = 0;  ///< person riding a motorcycle (0: none)
  int rider_variant = 0;
};

/// A pedestrian.
struct Pedestrian {
  uint32_t id = 0;
  int variant = 0;
  Activity activity = Activity::kWalk;
  enum class Route { kRing, kCrossing, kFixed } route = Route::kRing;
  int bi = 0, bj = 0;      ///< block (ring) or intersection (crossing)
  int arm = 0;             ///< crossing arm 0..3
  double p = 0;            ///< position along the ring perimeter or the crossing (m)
  int dir = 1;
  float speed = 1.3f;
  bool crossing_now = false;
  Vec3 position;           ///< current world position (ground)
  float yaw = 0;
  float phase0 = 0;        ///< animation phase offset
};

/// A lane position a leader can occupy (used to let the ego take part in car following).
struct LaneSlot {
  bool valid = false;
  int axis = 0, line = 0, dir = 1, lane = 0;
  double s = 0;
  float half_length = 2.3f;
};

/// The dynamic population of the town.
class Traffic {
 public:
  /// Places vehicles and pedestrians. Showcase vehicles of every class come towards the ego on
  /// its first road.
  void populate(const TownLayout& town, uint32_t seed,
                const std::array<VehicleModel, kVehicleKinds>& models, uint32_t& next_id);
  /// Advances by dt seconds to time t (the time after the step). `ego` is treated as a vehicle.
  void step(double t, double dt, const LaneSlot& ego);

  const std::vector<Vehicle>& vehicles() const { return vehicles_; }
  const std::vector<Pedestrian>& pedestrians() const { return pedestrians_; }
  /// World pose of a vehicle (ground under the centre).
  Mat4 vehiclePose(const Vehicle& v) const;
  Vec3 vehiclePosition(const Vehicle& v) const;
  /// Lateral offset of a lane from the road centre line, to the right of travel (m).
  static float laneOffset(int lane) { return 1.75f + 3.5f * lane; }
  /// Gap (m) that a vehicle at slot `me` has to the nearest leader on its lane (1e9 if none).
  double leaderGap(const LaneSlot& me, uint32_t self_id, const LaneSlot& ego) const;
  /// Distance to the next stop line with a light that is not green and can still be stopped
  /// for at speed v (1e9 if none).
  double redStopDistance(int axis, int line, int dir, double s, double v, double t) const;

 private:
  void stepPedestrian(Pedestrian& p, double t, double dt);

  const TownLayout* town_ = nullptr;
  const std::array<VehicleModel, kVehicleKinds>* models_ = nullptr;
  std::vector<Vehicle> vehicles_;
  std::vector<Pedestrian> pedestrians_;
};

}  // namespace world
}  // namespace viper
