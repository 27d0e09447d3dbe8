#include "ego.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
constexpr float B = RoadDims::kBlock;
Vec3 dirOf(std::pair<int, int> a, std::pair<int, int> b) {
  return {float(b.first - a.first), float(b.second - a.second), 0};
}
}  // namespace

void Ego::init(const TownLayout& town, EgoMode mode) {
  town_ = &town;
  mode_ = mode;
  const auto& r = town.route();
  const float off = mode == EgoMode::kWalk ? RoadDims::kWalkOffset
                    : mode == EgoMode::kRide ? Traffic::laneOffset(1) : Traffic::laneOffset(0);
  const float turn = 10.0f;  // the curve starts this far before the intersection centre
  auto add = [&](Vec3 p) {
    if (!pts_.empty() && length(p - pts_.back()) < 1e-3f) return;
    cum_.push_back(pts_.empty() ? 0.0 : cum_.back() + length(p - pts_.back()));
    pts_.push_back(p);
  };
  stop_s_.assign(r.size(), -1.0);
  for (size_t k = 0; k + 1 < r.size(); ++k) {
    Vec3 d = dirOf(r[k], r[k + 1]), right{d.y, -d.x, 0};
    Vec3 a = town.intersection(r[k].first, r[k].second) + right * off;
    Vec3 b = town.intersection(r[k + 1].first, r[k + 1].second) + right * off;
    bool turn_in = k > 0 && length(dirOf(r[k - 1], r[k]) - d) > 0.1f;
    bool turn_out = k + 2 < r.size() && length(dirOf(r[k + 1], r[k + 2]) - d) > 0.1f;
    Vec3 start = k == 0 ? a + d * (B * 0.5f) : a + d * (turn_in ? turn : 0.0f);
    Vec3 end = b - d * (turn_out ? turn : 0.0f);
    add(start);
    edge_start_s_.push_back(cum_.back());
    add(end);
    edge_end_s_.push_back(cum_.back());
    stop_s_[k + 1] = cum_.back() - (RoadDims::kStopLine - (turn_out ? turn : 0.0f)) - 1.0;
    if (turn_out) {
      Vec3 d2 = dirOf(r[k + 1], r[k + 2]), right2{d2.y, -d2.x, 0};
      Vec3 ctrl = town.intersection(r[k + 1].first, r[k + 1].second) + right * off + right2 * off;
      Vec3 next = town.intersection(r[k + 1].first, r[k + 1].second) + right2 * off + d2 * turn;
      for (int n = 1; n < 12; ++n) {
        float u = n / 12.0f;
        add(end * ((1 - u) * (1 - u)) + ctrl * (2 * u * (1 - u)) + next * (u * u));
      }
    }
  }
  s_ = 0;
  v_ = mode == EgoMode::kWalk ? 1.4 : 6.0;
}

int Ego::edgeAt(double s) const {
  for (size_t k = 0; k < edge_start_s_.size(); ++k)
    if (s >= edge_start_s_[k] && s <= edge_end_s_[k]) return int(k);
  return -1;
}

Vec3 Ego::pointAt(double s) const {
  s = std::clamp(s, 0.0, cum_.back());
  size_t k = std::upper_bound(cum_.begin(), cum_.end(), s) - cum_.begin();
  if (k >= pts_.size()) return pts_.back();
  if (k == 0) return pts_.front();
  double seg = cum_[k] - cum_[k - 1];
  float u = seg > 0 ? float((s - cum_[k - 1]) / seg) : 0.0f;
  return pts_[k - 1] * (1 - u) + pts_[k] * u;
}

LaneSlot Ego::laneSlot() const {
  LaneSlot slot;
  int e = edgeAt(s_);
  if (e < 0 || mode_ == EgoMode::kWalk) return slot;
  const auto& r = town_->route();
  Vec3 d = dirOf(r[e], r[e + 1]);
  slot.valid = true;
  slot.axis = d.x != 0 ? 0 : 1;
  slot.dir = int(d.x + d.y);
  slot.line = slot.axis == 0 ? r[e].second : r[e].first;
  slot.lane = mode_ == EgoMode::kRide ? 1 : 0;
  Vec3 p = pointAt(s_);
  // Traffic's lane coordinate is relative to the town's intersection (0, 0).
  const Vec3 o = town_->intersection(0, 0);
  slot.s = slot.axis == 0 ? p.x - o.x : p.y - o.y;
  slot.half_length = mode_ == EgoMode::kRide ? 1.0f : 2.3f;
  return slot;
}

void Ego::step(const Traffic& traffic, double t, double dt) {
  t_ = t;
  if (dt <= 0) return;
  if (mode_ == EgoMode::kWalk) {
    s_ = std::min(s_ + 1.4 * dt, cum_.back());
    return;
  }
  const double vmax = mode_ == EgoMode::kRide ? 11.0 : 10.0, brake = 6.0, accel = 2.5;
  double room = cum_.back() - s_;
  const auto& r = town_->route();
  for (size_t k = 1; k < stop_s_.size(); ++k) {
    if (stop_s_[k] < s_ || k + 1 >= r.size()) continue;
    Vec3 d = dirOf(r[k - 1], r[k]);
    int axis = d.x != 0 ? 0 : 1;
    double dist = stop_s_[k] - s_;
    bool green = town_->lightAt(r[k].first, r[k].second, axis, t) == LightColor::kGreen;
    if (!green && dist >= v_ * v_ / (4 * brake) - 0.5) room = std::min(room, dist);
    break;
  }
  LaneSlot me = laneSlot();
  if (me.valid) {
    LaneSlot none;
    room = std::min(room, traffic.leaderGap(me, 0, none) - 4.0);
  }
  room = std::max(0.0, room);
  double target = std::min(vmax, std::sqrt(2 * brake * room));
  // Slow down to a turning speed before and in the curves at intersections.
  const double v_turn = mode_ == EgoMode::kRide ? 5.5 : 5.0, turn_brake = 3.0;
  const int edge = edgeAt(s_);
  if (edge < 0) target = std::min(target, v_turn);
  for (size_t k = 0; k + 1 < edge_start_s_.size(); ++k) {
    if (edge_end_s_[k] < s_ || edge_start_s_[k + 1] <= edge_end_s_[k] + 0.1) continue;
    target = std::min(target, std::sqrt(v_turn * v_turn + 2 * turn_brake * (edge_end_s_[k] - s_)));
    break;
  }
  v_ = target < v_ ? std::max(target, v_ - 2 * brake * dt) : std::min(target, v_ + accel * dt);
  if (room < 0.3) v_ = 0;
  double prev_yaw_s = s_;
  s_ = std::min(s_ + v_ * dt, cum_.back());
  // Motorcycle lean follows the turn rate.
  Vec3 a0 = pointAt(prev_yaw_s + 1.0) - pointAt(prev_yaw_s - 1.0);
  Vec3 a1 = pointAt(s_ + 1.0) - pointAt(s_ - 1.0);
  float dyaw = std::atan2(cross(a0, a1).z, dot(a0, a1));
  // Lean angle of a motorcycle in a curve: atan(v * yaw_rate / g), damped.
  const float lean = std::atan(float(v_) * dyaw / float(dt) / 9.81f);
  lean_ = 0.8f * lean_ + 0.2f * std::clamp(lean, -0.3f, 0.3f);
}

Vec3 Ego::position() const { return transformPoint(cameraPose(), {0, 0, 0}); }

Mat4 Ego::cameraPose() const {
  Vec3 p = pointAt(s_);
  Vec3 tangent = pointAt(s_ + 2.0) - pointAt(s_ - 2.0);
  float yaw = std::atan2(tangent.y, tangent.x);
  float t = float(t_), roll = 0, pitch = 0;
  if (mode_ == EgoMode::kDrive) {
    p.z = 1.5f;
  } else if (mode_ == EgoMode::kRide) {
    p.z = 1.25f;
    roll = -lean_ + 0.03f * std::sin(t * 1.7f);
    pitch = 0.01f * std::sin(t * 2.3f);
  } else {
    float step_phase = float(s_) / 0.75f * kPi;
    p.z = RoadDims::kCurb + 1.62f + 0.025f * std::cos(2 * step_phase);
    roll = 0.01f * std::sin(step_phase);
    yaw += 0.03f * std::sin(t * 0.4f);
  }
  return pose(p, yaw, roll, pitch);
}

Mat4 Ego::viewMatrix() const {
  // OpenGL camera axes in the body frame: x_gl = -y, y_gl = z, z_gl = -x.
  Mat4 body_to_gl;
  body_to_gl.at(0, 0) = 0;  body_to_gl.at(1, 0) = -1; body_to_gl.at(2, 0) = 0;
  body_to_gl.at(0, 1) = 0;  body_to_gl.at(1, 1) = 0;  body_to_gl.at(2, 1) = 1;
  body_to_gl.at(0, 2) = -1; body_to_gl.at(1, 2) = 0;  body_to_gl.at(2, 2) = 0;
  return rigidInverse(cameraPose() * body_to_gl);
}

}  // namespace world
}  // namespace viper
