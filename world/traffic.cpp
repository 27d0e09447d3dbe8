#include "traffic.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
constexpr float B = RoadDims::kBlock;
constexpr float kBrake = 6.0f;   // comfortable deceleration (m/s^2)
constexpr float kAccel = 2.5f;
constexpr float kRingSide = RoadDims::kBlock - 2 * RoadDims::kWalkOffset;

float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * float(rng() % 100000u) / 100000.0f;
}

int axisCount(const TownLayout& t, int axis) { return axis == 0 ? t.nx() : t.ny(); }

Vec3 carColor(std::mt19937& rng) {
  static const Vec3 palette[] = {{0.8f, 0.1f, 0.1f}, {0.1f, 0.2f, 0.6f}, {0.9f, 0.9f, 0.9f},
                                 {0.15f, 0.15f, 0.15f}, {0.6f, 0.6f, 0.62f}, {0.2f, 0.45f, 0.25f},
                                 {0.9f, 0.75f, 0.2f}, {0.45f, 0.2f, 0.1f}};
  return palette[rng() % 8];
}
}  // namespace

Vec3 Traffic::vehiclePosition(const Vehicle& v) const {
  Vec3 d = v.axis == 0 ? Vec3{float(v.dir), 0, 0} : Vec3{0, float(v.dir), 0};
  Vec3 right{d.y, -d.x, 0};
  // Lanes are simulated in the town's own indices; a city's town sits at its origin.
  const auto [oi, oj] = town_->origin();
  const double s = v.s + (v.axis == 0 ? oi : oj) * double(B);
  const float line = (v.line + (v.axis == 0 ? oj : oi)) * B;
  Vec3 p = v.axis == 0 ? Vec3{float(s), line, 0} : Vec3{line, float(s), 0};
  return p + right * laneOffset(v.lane);
}

Mat4 Traffic::vehiclePose(const Vehicle& v) const {
  float yaw = v.axis == 0 ? (v.dir > 0 ? 0.0f : kPi) : (v.dir > 0 ? 0.5f * kPi : -0.5f * kPi);
  return pose(vehiclePosition(v), yaw);
}

void Traffic::populate(const TownLayout& town, uint32_t seed,
                       const std::array<VehicleModel, kVehicleKinds>& models, uint32_t& next_id) {
  town_ = &town;
  models_ = &models;
  std::mt19937 rng(seed ^ 0x9e3779b9u);
  auto newVehicle = [&](int kind, int axis, int line, int dir, int lane, double s) {
    // Nobody starts inside an intersection: move such a vehicle back behind the stop line.
    const double nearest = std::round(s / B) * B;
    if (std::fabs(s - nearest) < 15.0) s = nearest - dir * 15.0;
    Vehicle v;
    v.id = next_id++;
    v.kind = kind;
    v.axis = axis, v.line = line, v.dir = dir, v.lane = lane, v.s = s;
    v.vmax = kind == kKindBus || kind == kKindTruck ? uniform(rng, 7, 9) : uniform(rng, 8.5f, 12);
    v.v = 0;  // everyone starts from rest, so that every vehicle can stop for its first red
    v.tint = kind == kKindBus ? Vec3{0.9f, 0.75f, 0.15f} : carColor(rng);
    if (kind == kKindMotorcycle) {
      v.rider_id = next_id++;
      v.rider_variant = int(rng() % kPersonVariants);
    }
    vehicles_.push_back(v);
  };
  // The ego's first road: opposite lanes get one vehicle of every class, coming towards it.
  const auto& r = town.route();
  int sx = r[1].first - r[0].first, sy = r[1].second - r[0].second;
  int show_axis = sx != 0 ? 0 : 1, show_dir = sx + sy, show_line = sx != 0 ? r[0].second : r[0].first;
  double ego_s = (show_axis == 0 ? r[0].first : r[0].second) * B + show_dir * B * 0.5;

  for (int axis = 0; axis < 2; ++axis)
    for (int line = 0; line < axisCount(town, 1 - axis); ++line)
      for (int dir : {1, -1})
        for (int lane = 0; lane < 2; ++lane) {
          double lo = -B * 0.5, hi = (axisCount(town, axis) - 0.5) * B;
          for (double s = lo + uniform(rng, 5, 40); s < hi - 8; s += uniform(rng, 35, 100)) {
            bool showcase = axis == show_axis && line == show_line && dir == -show_dir;
            if (showcase && std::fabs(s - (ego_s + show_dir * 110)) < 110) continue;
            unsigned k = rng() % 100;
            int kind = k < 52 ? kKindCar : k < 67 ? kKindVan : k < 79 ? kKindTruck
                                                    : k < 92 ? kKindMotorcycle : kKindBus;
            if (kind == kKindBus && lane == 0) kind = kKindCar;
            newVehicle(kind, axis, line, dir, lane, s);
          }
        }
  const int show_kinds[5] = {kKindMotorcycle, kKindBus, kKindCar, kKindTruck, kKindVan};
  for (int n = 0; n < 5; ++n)
    newVehicle(show_kinds[n], show_axis, show_line, -show_dir, n == 1 || n == 3 ? 1 : n % 2,
               ego_s + show_dir * (30.0 + 38.0 * n));

  // Pedestrians: walkers and standers on every block ring, sitters on half the chairs, one
  // crossing pedestrian per inner intersection.
  auto newPed = [&](Pedestrian p) {
    p.id = next_id++;
    p.variant = int(rng() % kPersonVariants);
    p.phase0 = uniform(rng, 0, 6.28f);
    p.speed = uniform(rng, 1.1f, 1.6f);
    pedestrians_.push_back(p);
  };
  for (int j = 0; j + 1 < town.ny(); ++j)
    for (int i = 0; i + 1 < town.nx(); ++i) {
      for (int k = 0; k < 6; ++k) {
        Pedestrian p;
        p.bi = i, p.bj = j;
        p.p = uniform(rng, 0, 4 * kRingSide);
        p.dir = rng() % 2 ? 1 : -1;
        p.activity = k < 5 ? Activity::kWalk : Activity::kStand;
        newPed(p);
      }
    }
  for (int c : town.chairs()) {
    if (rng() % 2) continue;
    const PropInstance& chair = town.props()[c];
    Pedestrian p;
    p.route = Pedestrian::Route::kFixed;
    p.activity = Activity::kSit;
    p.position = chair.position + Vec3{std::cos(chair.yaw), std::sin(chair.yaw), 0} * 0.03f;
    p.yaw = chair.yaw;
    newPed(p);
  }
  for (int j = 1; j + 1 < town.ny(); ++j)
    for (int i = 1; i + 1 < town.nx(); ++i) {
      Pedestrian p;
      p.route = Pedestrian::Route::kCrossing;
      p.bi = i, p.bj = j;
      p.arm = int(rng() % 4);
      p.p = 0;
      p.dir = 1;
      p.activity = Activity::kStand;
      newPed(p);
    }
  LaneSlot none;
  step(0.0, 0.0, none);
}

double Traffic::redStopDistance(int axis, int line, int dir, double s, double v, double t) const {
  int n = axisCount(*town_, axis), m = axisCount(*town_, 1 - axis);
  if (line < 0 || line > m - 1) return 1e9;
  const double stop = RoadDims::kStopLine;
  int k = dir > 0 ? int(std::ceil((s + stop + 0.01) / B)) : int(std::floor((s - stop - 0.01) / B));
  if (k < 0 || k > n - 1) return 1e9;
  double dist = dir > 0 ? (k * B - stop) - s : s - (k * B + stop);
  int i = axis == 0 ? k : line, j = axis == 0 ? line : k;
  if (town_->lightAt(i, j, axis, t) == LightColor::kGreen) return 1e9;
  // Past the point where even a hard stop (twice the comfortable deceleration) is possible: drive
  // on (the all-red phase clears the junction). Braking itself starts at the comfortable distance.
  if (dist < v * v / (4.0 * kBrake) - 0.5) return 1e9;
  return dist;
}

double Traffic::leaderGap(const LaneSlot& me, uint32_t self_id, const LaneSlot& ego) const {
  double best = 1e9;
  auto consider = [&](double s, float half_len) {
    double ahead = me.dir * (s - me.s);
    if (ahead <= 0) return;
    best = std::min(best, ahead - half_len - me.half_length);
  };
  for (const Vehicle& o : vehicles_) {
    if (o.id == self_id || o.axis != me.axis || o.line != me.line || o.dir != me.dir ||
        o.lane != me.lane)
      continue;
    consider(o.s, (*models_)[o.kind].length_m * 0.5f);
  }
  if (ego.valid && ego.axis == me.axis && ego.line == me.line && ego.dir == me.dir &&
      ego.lane == me.lane)
    consider(ego.s, ego.half_length);
  return best;
}

void Traffic::step(double t, double dt, const LaneSlot& ego) {
  if (dt > 0) {
    std::vector<double> new_v(vehicles_.size());
    for (size_t n = 0; n < vehicles_.size(); ++n) {
      const Vehicle& v = vehicles_[n];
      LaneSlot me{true, v.axis, v.line, v.dir, v.lane, v.s, (*models_)[v.kind].length_m * 0.5f};
      double gap = leaderGap(me, v.id, ego) - 3.0;
      double stop = redStopDistance(v.axis, v.line, v.dir, v.s + v.dir * me.half_length, v.v, t) - 0.5;
      double room = std::max(0.0, std::min(gap, stop));
      double target = std::min<double>(v.vmax, std::sqrt(2.0 * kBrake * room));
      new_v[n] = target < v.v ? std::max(target, v.v - 2.0 * kBrake * dt)
                              : std::min(target, v.v + kAccel * dt);
      if (room < 0.3) new_v[n] = 0;
    }
    for (size_t n = 0; n < vehicles_.size(); ++n) {
      Vehicle& v = vehicles_[n];
      v.v = new_v[n];
      v.s += v.dir * v.v * dt;
      double lo = -B * 0.5, hi = (axisCount(*town_, v.axis) - 0.5) * B;
      // Leaving the town at one end, re-entering at the other (far from the ego route).
      if (v.s > hi) v.s = lo + (v.s - hi);
      if (v.s < lo) v.s = hi - (lo - v.s);
    }
  }
  for (Pedestrian& p : pedestrians_) stepPedestrian(p, t, dt);
}

void Traffic::stepPedestrian(Pedestrian& p, double t, double dt) {
  if (p.route == Pedestrian::Route::kFixed) return;
  if (p.route == Pedestrian::Route::kRing) {
    const double perimeter = 4 * kRingSide;
    if (p.activity == Activity::kWalk) p.p = std::fmod(p.p + p.dir * p.speed * dt + perimeter, perimeter);
    int side = std::min(3, int(p.p / kRingSide));
    double along = p.p - side * kRingSide;
    const Vec3 o = town_->intersection(p.bi, p.bj);
    const float w = RoadDims::kWalkOffset;
    const Vec3 corners[4] = {{o.x + w, o.y + w, 0}, {o.x + B - w, o.y + w, 0},
                             {o.x + B - w, o.y + B - w, 0}, {o.x + w, o.y + B - w, 0}};
    Vec3 a = corners[side], b = corners[(side + 1) % 4];
    Vec3 u = normalize(b - a);
    p.position = a + u * float(along);
    p.position.z = RoadDims::kCurb;
    if (p.activity == Activity::kWalk) {
      p.yaw = std::atan2(u.y * p.dir, u.x * p.dir);
    } else {
      p.yaw = std::atan2(-u.x, u.y);  // facing the road
    }
    return;
  }
  // Crossing: wait on the curb; cross while the cars on this arm have a long enough red.
  const Vec3 c = town_->intersection(p.bi, p.bj);
  const Vec3 e{std::round(std::cos(p.arm * kPi * 0.5f)), std::round(std::sin(p.arm * kPi * 0.5f)), 0};
  const Vec3 q{-e.y, e.x, 0};
  const int axis = e.x != 0 ? 0 : 1;
  const double half = RoadDims::kWalkOffset, length = 2 * half;
  if (!p.crossing_now && dt > 0) {
    double red_left = town_->secondsOfRedLeft(p.bi, p.bj, axis, t);
    if (red_left > length / p.speed + 1.0 && red_left < 17.0) p.crossing_now = true;
  }
  if (p.crossing_now) {
    p.p += p.speed * dt;
    if (p.p >= length) {
      p.p = 0;
      p.dir = -p.dir;
      p.crossing_now = false;
    }
  }
  p.activity = p.crossing_now ? Activity::kWalk : Activity::kStand;
  double along = p.dir > 0 ? -half + p.p : half - p.p;
  p.position = c + e * float(half) + q * float(along);
  p.position.z = std::fabs(along) > RoadDims::kRoadHalf ? RoadDims::kCurb : 0.0f;
  Vec3 heading = q * float(p.dir);
  p.yaw = std::atan2(heading.y, heading.x);
}

}  // namespace world
}  // namespace viper
