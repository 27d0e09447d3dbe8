#include "world_scene.h"

#include "classes.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
// Object id ranges: static chunks from 1, props, lights, then people and vehicles.
constexpr uint32_t kPropIds = 100000, kLightIds = 200000, kDynamicIds = 300000;
constexpr uint32_t kSkyId = 900000, kParticlesId = 900001, kGlareId = 900002;
}  // namespace

WorldScene::WorldScene(const Options& options) : options_(options) {
  town_.generate(options.seed, float(options.route_length_m), meshes_, options.in_city ? &options.city : nullptr);
  models_ = buildVehicleModels(meshes_);
  person_meshes_ = buildPersonMeshes(meshes_);
  addEffectMeshes(meshes_, options.seed);
  uint32_t next_id = kDynamicIds;
  traffic_.populate(town_, options.seed, models_, next_id);
  ego_.init(town_, options.ego);
  const auto& r = town_.route();
  float heading = std::atan2(float(r[1].second - r[0].second), float(r[1].first - r[0].first));
  cond_ = conditionParams(options.condition, heading);
  const float aspect = float(options.width) / float(options.height);
  proj_ = perspective(float(options.fov_deg) * kPi / 180.0f, aspect, 0.3f, 600.0f);
}

void WorldScene::step() {
  const double dt = 1.0 / options_.fps;
  t_ += dt;
  traffic_.step(t_, dt, ego_.laneSlot());
  ego_.step(traffic_, t_, dt);
}

bool WorldScene::visible(Vec3 c, float radius) const {
  Vec3 d = c - cam_pos_;
  float dist = length(d);
  if (dist - radius > draw_distance_m_) return false;
  if (dist < radius) return true;
  // View-space sphere test against the four side planes of the frustum.
  Vec3 v = transformPoint(view_, c);
  if (v.z - radius > 0) return false;
  float fy = proj_.at(1, 1), fx = proj_.at(0, 0);
  float sy = std::sqrt(1 + fy * fy), sx = std::sqrt(1 + fx * fx);
  if ((fy * v.y + v.z) / sy > radius || (-fy * v.y + v.z) / sy > radius) return false;
  if ((fx * v.x + v.z) / sx > radius || (-fx * v.x + v.z) / sx > radius) return false;
  return true;
}

FrameLighting WorldScene::lighting() const {
  FrameLighting l;
  l.cond = cond_;
  l.cam_pos = cam_pos_;
  const float lamps = cond_.night;
  if (lamps > 0) {
    // The street lamps nearest to a point ahead of the camera light the scene.
    Vec3 focus = cam_pos_ + cam_fwd_ * 30.0f;
    std::vector<std::pair<float, int>> near;
    const auto& heads = town_.lampHeads();
    for (size_t i = 0; i < heads.size(); ++i) {
      float d = length(heads[i] - focus);
      if (d < 90.0f) near.push_back({d, int(i)});
    }
    std::sort(near.begin(), near.end());
    for (const auto& n : near) {
      if (l.light_count == kMaxLights) break;
      l.light_pos[l.light_count] = heads[n.second];
      l.light_color[l.light_count] = Vec3{1.0f, 0.78f, 0.45f} * (2.0f * lamps);
      ++l.light_count;
    }
    if (options_.ego != EgoMode::kWalk) {
      l.head_on = lamps;
      l.head_pos = cam_pos_ - Vec3{0, 0, 0.8f};
      l.head_dir = normalize(cam_fwd_ + Vec3{0, 0, -0.04f});
    }
  }
  return l;
}

void WorldScene::drawPerson(Renderer& r, uint32_t id, int variant, Activity a, float phase,
                            const Mat4& world) {
  std::vector<Mat4> bones = personPose(a, phase);
  DrawRequest d;
  d.object_id = id;
  d.class_id = kPerson;
  d.part = "body";
  d.mesh = person_meshes_[variant];
  d.world = world;
  d.bones = &bones;
  r.draw(d);
}

void WorldScene::drawVehicle(Renderer& r, const Vehicle& v) {
  const VehicleModel& m = models_[v.kind];
  Vec3 p = traffic_.vehiclePosition(v);
  const int lod = length(p - cam_pos_) > kVehicleLodDistance ? 1 : 0;
  DrawRequest d;
  d.object_id = v.id;
  d.class_id = m.class_id;
  d.world = traffic_.vehiclePose(v);
  auto part = [&](const char* name, int mesh, Vec3 tint, float emissive) {
    d.part = name;
    d.mesh = mesh;
    d.tint = tint;
    d.emissive = emissive;
    r.draw(d);
  };
  const float lights_on = std::max(cond_.night, 0.0f);
  part("body", m.body[lod], v.tint, 0.0f);
  part("windows", m.windows[lod], {1, 1, 1}, 0.0f);
  part("wheels", m.wheels[lod], {1, 1, 1}, 0.0f);
  part("headlights", m.headlights[lod], {1, 1, 1}, 3.0f * lights_on);
  const bool braking = v.v < 2.0;
  part("taillights", m.taillights[lod], {1, 1, 1}, 2.5f * lights_on + (braking ? 1.5f : 0.0f));
  if (v.rider_id)
    drawPerson(r, v.rider_id, v.rider_variant, Activity::kSit, float(t_),
               d.world * translation({-0.35f, 0, 0.36f}));
}

void WorldScene::render(Renderer& r, OracleFrame* oracle) {
  view_ = ego_.viewMatrix();
  const Mat4 cam = ego_.cameraPose();
  cam_pos_ = transformPoint(cam, {0, 0, 0});
  cam_fwd_ = transformPoint(cam, {1, 0, 0}) - cam_pos_;
  draw_distance_m_ = cond_.particles == Particles::kSnow ? 140.0f : 180.0f;
  if (oracle) {
    for (int i = 0; i < 16; ++i) {
      oracle->view.data()[i] = view_.m[i];
      oracle->projection.data()[i] = proj_.m[i];
      oracle->map_from_camera_body.data()[i] = double(cam.m[i]);
    }
    oracle->time_s = t_;
  }
  r.beginFrame(view_, proj_, lighting());

  // Opaque objects are issued roughly front to back, so that early depth tests save shading.
  struct Pending {
    float key;
    int kind;  // 0 chunk, 1 prop, 2 traffic light, 3 vehicle, 4 pedestrian
    int index;
    bool operator<(const Pending& o) const {
      return key != o.key ? key < o.key : kind != o.kind ? kind < o.kind : index < o.index;
    }
  };
  std::vector<Pending> pending;
  const auto& chunks = town_.chunks();
  for (size_t i = 0; i < chunks.size(); ++i) {
    const StaticChunk& c = chunks[i];
    if (!visible(c.center, c.radius)) continue;
    // The outer ground is huge and mostly hidden: last.
    float key = c.radius > 1000.0f ? 1e9f : length(c.center - cam_pos_) - 0.5f * c.radius;
    pending.push_back({key, 0, int(i)});
  }
  const auto& props = town_.props();
  for (size_t i = 0; i < props.size(); ++i)
    if (visible(props[i].position, 1.2f))
      pending.push_back({length(props[i].position - cam_pos_), 1, int(i)});
  const auto& lights = town_.lights();
  for (size_t i = 0; i < lights.size(); ++i)
    if (visible(lights[i].position + Vec3{0, 0, 4}, 6.0f))
      pending.push_back({length(lights[i].position - cam_pos_), 2, int(i)});
  const auto& vehicles = traffic_.vehicles();
  for (size_t i = 0; i < vehicles.size(); ++i) {
    const VehicleModel& m = models_[vehicles[i].kind];
    Vec3 p = traffic_.vehiclePosition(vehicles[i]);
    if (visible(p + Vec3{0, 0, m.height_m * 0.5f}, m.length_m * 0.55f + 1.0f))
      pending.push_back({length(p - cam_pos_), 3, int(i)});
  }
  const auto& peds = traffic_.pedestrians();
  for (size_t i = 0; i < peds.size(); ++i) {
    const Pedestrian& p = peds[i];
    if (!visible(p.position + Vec3{0, 0, 0.9f}, 1.0f)) continue;
    if (length(p.position - cam_pos_) < 1.0f) continue;
    pending.push_back({length(p.position - cam_pos_), 4, int(i)});
  }
  std::sort(pending.begin(), pending.end());

  static const char* kLampParts[3] = {"lamp_red", "lamp_yellow", "lamp_green"};
  const int lamp_meshes[3] = {meshes_.find("trafficlight_lamp_red"),
                              meshes_.find("trafficlight_lamp_yellow"),
                              meshes_.find("trafficlight_lamp_green")};
  const int pole = meshes_.find("trafficlight_pole"), housing = meshes_.find("trafficlight_housing");
  for (const Pending& item : pending) {
    DrawRequest d;
    if (item.kind == 0) {
      const StaticChunk& c = chunks[item.index];
      d.object_id = uint32_t(item.index + 1);
      d.class_id = c.class_id;
      d.part = c.class_id == kRoad && meshes_.at(c.mesh).name.find("markings") != std::string::npos
                   ? "markings" : "surface";
      d.mesh = c.mesh;
      d.world = c.world;
      r.draw(d);
    } else if (item.kind == 1) {
      const PropInstance& p = props[item.index];
      d.object_id = kPropIds + uint32_t(item.index);
      d.class_id = p.class_id;
      d.mesh = p.mesh;
      d.world = p.world;
      r.draw(d);
    } else if (item.kind == 2) {
      const TrafficLightSite& s = lights[item.index];
      LightColor color = town_.lightAt(s.i, s.j, s.axis, t_);
      int active = color == LightColor::kRed ? 0 : color == LightColor::kYellow ? 1 : 2;
      d.object_id = kLightIds + uint32_t(item.index);
      d.class_id = kTrafficLight;
      d.world = s.world;
      d.part = "pole";
      d.mesh = pole;
      r.draw(d);
      d.part = "housing";
      d.mesh = housing;
      r.draw(d);
      for (int k = 0; k < 3; ++k) {
        d.part = kLampParts[k];
        d.mesh = lamp_meshes[k];
        d.tint = k == active ? Vec3{1, 1, 1} : Vec3{0.15f, 0.15f, 0.15f};
        d.emissive = k == active ? 1.5f : 0.0f;
        r.draw(d);
      }
    } else if (item.kind == 3) {
      drawVehicle(r, vehicles[item.index]);
    } else {
      const Pedestrian& p = peds[item.index];
      float phase = p.phase0 + float(t_) * (p.activity == Activity::kWalk ? p.speed * 4.2f : 1.0f);
      drawPerson(r, p.id, p.variant, p.activity, phase, pose(p.position, p.yaw));
    }
  }
  r.drawSky(kSkyId);
  if (!options_.no_effects) {
    r.drawParticles(kParticlesId, t_);
    r.drawGlare(kGlareId);
  }
}

}  // namespace world
}  // namespace viper
