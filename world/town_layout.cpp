#include "town_layout.h"

#include "classes.h"
#include "props.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
constexpr float B = RoadDims::kBlock;
constexpr double kCycle = 32.0;
// Streams of a city's per-place generators (with the city seed and the global indices).
constexpr uint32_t kBlockContent = 1, kLightPhase = 2;

float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * float(rng() % 100000u) / 100000.0f;
}

// Flat rectangle on the ground plane at height z, split into cells of at most `cell` metres:
// lighting is per vertex, and lamp light pools need the vertices.
void groundQuad(MeshData& m, float x0, float y0, float x1, float y1, float z, Vec3 c,
                float cell = 1e9f) {
  int nx = std::max(1, int(std::ceil((x1 - x0) / cell))), ny = std::max(1, int(std::ceil((y1 - y0) / cell)));
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      float ax = x0 + (x1 - x0) * i / nx, bx = x0 + (x1 - x0) * (i + 1) / nx;
      float ay = y0 + (y1 - y0) * j / ny, by = y0 + (y1 - y0) * (j + 1) / ny;
      m.addQuad({ax, ay, z}, {bx, ay, z}, {bx, by, z}, {ax, by, z}, c);
    }
}

constexpr float kRoadCell = 3.5f;

// A slab from z = -0.1 to `top` (so curbs have visible sides), its top tessellated.
void slab(MeshData& m, float x0, float y0, float x1, float y1, float top, Vec3 c) {
  const float bottom = -0.1f;
  const Vec3 p[8] = {{x0, y0, bottom}, {x1, y0, bottom}, {x1, y1, bottom}, {x0, y1, bottom},
                     {x0, y0, top},    {x1, y0, top},    {x1, y1, top},    {x0, y1, top}};
  m.addQuad(p[0], p[1], p[5], p[4], c);
  m.addQuad(p[1], p[2], p[6], p[5], c);
  m.addQuad(p[2], p[3], p[7], p[6], c);
  m.addQuad(p[3], p[0], p[4], p[7], c);
  groundQuad(m, x0, y0, x1, y1, top, c, 4.0f);
}

MeshData lightPoleMesh() {
  MeshData m;
  Vec3 metal{0.3f, 0.32f, 0.3f};
  m.addCylinder(Mat4(), 0.13f, 6.0f, 8, metal);
  m.addBox(translation({0, -2.6f, 5.9f}), {0.07f, 2.6f, 0.07f}, metal);
  return m;
}
MeshData lightHousingMesh() {
  MeshData m;
  m.addBox(translation({0, -4.6f, 5.1f}), {0.2f, 0.25f, 0.75f}, {0.12f, 0.12f, 0.1f});
  m.addBox(translation({0.05f, -4.6f, 5.1f}), {0.2f, 0.4f, 0.9f}, {0.2f, 0.2f, 0.18f});
  return m;
}
MeshData lightLampMesh(float z, Vec3 color) {
  MeshData m;
  m.addCylinder(translation({0.25f, -4.6f, z}) * rotationY(kPi * 0.5f), 0.17f, 0.05f, 10, color);
  return m;
}
}  // namespace

LightColor TownLayout::lightAt(int i, int j, int axis, double t) const {
  double phase = std::fmod(t + phase_offset_s_[j * nx_ + i], kCycle);
  double start = axis == 0 ? 0.0 : 16.0;
  double local = std::fmod(phase - start + kCycle, kCycle);
  if (local < 11.0) return LightColor::kGreen;
  if (local < 14.0) return LightColor::kYellow;
  return LightColor::kRed;
}

double TownLayout::secondsOfRedLeft(int i, int j, int axis, double t) const {
  double phase = std::fmod(t + phase_offset_s_[j * nx_ + i], kCycle);
  double start = axis == 0 ? 0.0 : 16.0;
  double local = std::fmod(phase - start + kCycle, kCycle);
  return local < 11.0 ? 0.0 : kCycle - local;
}

void TownLayout::placeTown(Route r, bool in_city) {
  int min_i = r[0].first, min_j = r[0].second, max_i = min_i, max_j = min_j;
  for (auto& p : r) {
    min_i = std::min(min_i, p.first), max_i = std::max(max_i, p.first);
    min_j = std::min(min_j, p.second), max_j = std::max(max_j, p.second);
  }
  const int margin = 2;
  for (auto& p : r) p.first += margin - min_i, p.second += margin - min_j;
  if (in_city) origin_i_ = min_i - margin, origin_j_ = min_j - margin;
  nx_ = max_i - min_i + 1 + 2 * margin;
  ny_ = max_j - min_j + 1 + 2 * margin;
  route_ = r;
}

void TownLayout::addChunk(const std::string& name, uint8_t class_id, MeshData m, Vec3 origin,
                          MeshLibrary& meshes) {
  if (m.indices.empty()) return;
  // A class-dependent shift of the origin keeps every chunk's matrix distinct.
  origin.x += 0.25f * class_id;
  for (size_t v = 0; v < m.vertexCount(); ++v) {
    m.positions[3 * v] -= origin.x;
    m.positions[3 * v + 1] -= origin.y;
    m.positions[3 * v + 2] -= origin.z;
  }
  StaticChunk c;
  c.class_id = class_id;
  c.mesh = meshes.add(name, class_id, std::move(m));
  c.world = translation(origin);
  c.center = meshes.at(c.mesh).center + origin;
  c.radius = meshes.at(c.mesh).radius;
  chunks_.push_back(c);
}

void TownLayout::addProp(uint8_t class_id, int mesh, Vec3 position, float yaw) {
  PropInstance p;
  p.class_id = class_id;
  p.mesh = mesh;
  p.position = position;
  p.yaw = yaw;
  p.world = pose(position, yaw);
  props_.push_back(p);
}

void TownLayout::generate(uint32_t seed, float route_length_m, MeshLibrary& meshes, const CityPlace* city) {
  std::mt19937 rng(seed);
  const int edges = routeEdges(route_length_m);
  placeTown(city ? routeInRegion(rng, edges, city->region) : randomWalk(rng, edges, {0, 0}, {1, 0}, nullptr),
            city != nullptr);
  setLightPhases(rng, city);

  meshes.add("trafficlight_pole", kTrafficLight, lightPoleMesh());
  meshes.add("trafficlight_housing", kTrafficLight, lightHousingMesh());
  meshes.add("trafficlight_lamp_red", kTrafficLight, lightLampMesh(5.6f, {0.9f, 0.1f, 0.05f}));
  meshes.add("trafficlight_lamp_yellow", kTrafficLight, lightLampMesh(5.1f, {0.9f, 0.7f, 0.05f}));
  meshes.add("trafficlight_lamp_green", kTrafficLight, lightLampMesh(4.6f, {0.1f, 0.9f, 0.3f}));
  meshes.add("firehydrant", kFireHydrant, fireHydrantMesh());
  meshes.add("chair", kChair, chairMesh());
  meshes.add("trashcan", kTrashCan, trashCanMesh());

  makeGround(meshes);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) makeRoadCell(i, j, meshes);
  for (int j = 0; j + 1 < ny_; ++j)
    for (int i = 0; i + 1 < nx_; ++i) {
      if (!city) {
        makeBlock(i, j, rng, meshes);
        continue;
      }
      std::seed_seq block_seed{city->city_seed, uint32_t(origin_i_ + i), uint32_t(origin_j_ + j), kBlockContent};
      std::mt19937 block_rng(block_seed);
      makeBlock(i, j, block_rng, meshes);
    }
}

void TownLayout::setLightPhases(std::mt19937& rng, const CityPlace* city) {
  phase_offset_s_.resize(nx_ * ny_);
  if (city) {
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        std::seed_seq light_seed{city->city_seed, uint32_t(origin_i_ + i), uint32_t(origin_j_ + j), kLightPhase};
        std::mt19937 light_rng(light_seed);
        phase_offset_s_[j * nx_ + i] = uniform(light_rng, 0.0f, float(kCycle));
      }
    return;
  }
  for (float& p : phase_offset_s_) p = uniform(rng, 0.0f, float(kCycle));
  // The first intersection on the route turns green for the ego as the sequence starts, so that
  // default sequences begin with motion rather than with a wait at a red light. (A city's lights
  // belong to the city: there the ego may start at a red light.)
  const int first_axis = route_[1].first != route_[0].first ? 0 : 1;
  phase_offset_s_[route_[1].second * nx_ + route_[1].first] = first_axis == 0 ? 0.0f : float(kCycle) - 16.0f;
}

void TownLayout::makeGround(MeshLibrary& meshes) {
  MeshData m;
  // Relative to intersection (0, 0), which is the origin of a town of its own.
  float lo = -3 * B, hix = (nx_ + 2) * B, hiy = (ny_ + 2) * B;
  // Ring of terrain around the town (the town's own blocks have their own ground).
  Vec3 grass{0.3f, 0.42f, 0.2f};
  groundQuad(m, lo, lo, hix, -B * 0.5f, -0.1f, grass);
  groundQuad(m, lo, (ny_ - 0.5f) * B, hix, hiy, -0.1f, grass);
  groundQuad(m, lo, -B * 0.5f, -B * 0.5f, (ny_ - 0.5f) * B, -0.1f, grass);
  groundQuad(m, (nx_ - 0.5f) * B, -B * 0.5f, hix, (ny_ - 0.5f) * B, -0.1f, grass);
  addChunk("ground_outer", kTerrain, std::move(m), {0, 0, 0}, meshes);
  chunks_.back().world = translation(intersection(0, 0) + Vec3{0.25f * kTerrain, 0, 0});
  chunks_.back().center = chunks_.back().center + intersection(0, 0);
}

void TownLayout::makeRoadCell(int i, int j, MeshLibrary& meshes) {
  const Vec3 c = intersection(i, j);
  const float h = RoadDims::kRoadHalf;
  const Vec3 asphalt{0.23f, 0.23f, 0.25f}, white{0.85f, 0.85f, 0.82f}, yellow{0.85f, 0.7f, 0.2f};
  MeshData road, marks, walk;
  groundQuad(road, c.x - h, c.y - h, c.x + h, c.y + h, 0, asphalt, kRoadCell);
  // Segments to +x and +y; the outer rim gets a half segment so roads leave the town.
  float xe = i + 1 < nx_ ? B - h : B * 0.5f, ye = j + 1 < ny_ ? B - h : B * 0.5f;
  groundQuad(road, c.x + h, c.y - h, c.x + xe, c.y + h, 0, asphalt, kRoadCell);
  groundQuad(road, c.x - h, c.y + h, c.x + h, c.y + ye, 0, asphalt, kRoadCell);
  if (i == 0) groundQuad(road, c.x - B * 0.5f, c.y - h, c.x - h, c.y + h, 0, asphalt, kRoadCell);
  if (j == 0) groundQuad(road, c.x - h, c.y - B * 0.5f, c.x + h, c.y - h, 0, asphalt, kRoadCell);
  const float z = 0.02f;
  for (int axis = 0; axis < 2; ++axis) {
    float end = axis == 0 ? xe : ye;
    auto quad = [&](float a0, float b0, float a1, float b1, Vec3 col) {
      if (axis == 0) groundQuad(marks, c.x + a0, c.y + b0, c.x + a1, c.y + b1, z, col);
      else groundQuad(marks, c.x + b0, c.y + a0, c.x + b1, c.y + a1, z, col);
    };
    float from = RoadDims::kStopLine, to = end - (end < B * 0.6f ? 0.0f : RoadDims::kStopLine);
    // Double yellow centre line, dashed lane lines.
    quad(from, -0.2f, to, -0.08f, yellow);
    quad(from, 0.08f, to, 0.2f, yellow);
    for (float s = from; s + 3.0f < to; s += 9.0f) {
      quad(s, -3.58f, s + 3.0f, -3.42f, white);
      quad(s, 3.42f, s + 3.0f, 3.58f, white);
    }
    // Edge lines.
    quad(from, -h + 0.3f, to, -h + 0.45f, white);
    quad(from, h - 0.45f, to, h - 0.3f, white);
  }
  // Crossings (zebra) on all four arms and stop lines on the approach (right-hand) side.
  for (int arm = 0; arm < 4; ++arm) {
    float yaw = arm * kPi * 0.5f;
    Mat4 r = rotationZ(yaw);
    auto rquad = [&](float a0, float b0, float a1, float b1, Vec3 col, MeshData& dst) {
      Vec3 p0 = transformPoint(r, {a0, b0, 0}), p1 = transformPoint(r, {a1, b1, 0});
      groundQuad(dst, c.x + std::min(p0.x, p1.x), c.y + std::min(p0.y, p1.y),
                 c.x + std::max(p0.x, p1.x), c.y + std::max(p0.y, p1.y), z, col);
    };
    for (float s = -h + 0.5f; s < h - 0.5f; s += 1.2f) rquad(7.5f, s, 10.5f, s + 0.6f, white, walk);
    rquad(11.2f, 0.2f, 11.6f, h - 0.3f, white, marks);
  }
  std::string name = "road_" + std::to_string(origin_i_ + i) + "_" + std::to_string(origin_j_ + j);
  addChunk(name, kRoad, std::move(road), c, meshes);
  marks.append(walk, Mat4());
  // Markings are road class too, but a separate mesh (its own draw, slightly above the asphalt).
  Vec3 mo = c;
  mo.y += 0.5f;
  addChunk(name + "_markings", kRoad, std::move(marks), mo, meshes);

  // Traffic lights: one per approach, on the right-hand corner, the arm over the lanes.
  for (int arm = 0; arm < 4; ++arm) {
    Vec3 d{std::cos(arm * kPi * 0.5f), std::sin(arm * kPi * 0.5f), 0};  // traffic heading
    d = {std::round(d.x), std::round(d.y), 0};
    Vec3 right{d.y, -d.x, 0};
    TrafficLightSite s;
    s.i = i;
    s.j = j;
    s.axis = d.x != 0 ? 0 : 1;
    s.position = c - d * 11.8f + right * 8.0f;
    s.position.z = RoadDims::kCurb;
    s.world = pose(s.position, std::atan2(-d.y, -d.x));
    lights_.push_back(s);
  }
}

void TownLayout::makeBlock(int i, int j, std::mt19937& rng, MeshLibrary& meshes) {
  const Vec3 o = intersection(i, j);
  const float in = RoadDims::kSidewalkOuter, out = RoadDims::kRoadHalf, top = RoadDims::kCurb;
  const float x0 = o.x + out, x1 = o.x + B - out, y0 = o.y + out, y1 = o.y + B - out;
  const float ix0 = o.x + in, ix1 = o.x + B - in, iy0 = o.y + in, iy1 = o.y + B - in;
  MeshData sidewalk, terrain, building, tree, veg, fence, infra, billboard, sign, barrier, trash;
  const Vec3 paving{0.55f, 0.53f, 0.5f};
  slab(sidewalk, x0, y0, x1, iy0, top, paving);
  slab(sidewalk, x0, iy1, x1, y1, top, paving);
  slab(sidewalk, x0, iy0, ix0, iy1, top, paving);
  slab(sidewalk, ix1, iy0, x1, iy1, top, paving);

  unsigned type = rng() % 20;  // 0-3 park, 4-6 plaza, else buildings
  const bool park = type < 4, plaza = type >= 4 && type < 7;
  if (plaza) slab(sidewalk, ix0, iy0, ix1, iy1, top - 0.01f, paving * 0.9f);
  else slab(terrain, ix0, iy0, ix1, iy1, top - 0.02f, {0.32f, 0.45f, 0.2f});

  // The four sides of the block: origin at the side's start, u along it, n pointing to the road.
  struct Side { Vec3 start; Vec3 u; Vec3 n; };
  const Side sides[4] = {{{ix0, iy0, top}, {1, 0, 0}, {0, -1, 0}},
                         {{ix1, iy0, top}, {0, 1, 0}, {1, 0, 0}},
                         {{ix1, iy1, top}, {-1, 0, 0}, {0, 1, 0}},
                         {{ix0, iy1, top}, {0, -1, 0}, {-1, 0, 0}}};
  const float side_len = ix1 - ix0;
  for (int s = 0; s < 4; ++s) {
    const Side& sd = sides[s];
    const float face_yaw = std::atan2(sd.n.y, sd.n.x);
    auto at = [&](float along, float off) { return sd.start + sd.u * along + sd.n * off; };
    // Street lamps at the curb, arm over the road.
    for (float a = 6.0f; a < side_len; a += 24.0f) {
      Vec3 p = at(a, in - out - 0.4f);
      addStreetLamp(infra, pose(p, face_yaw));
      lamp_heads_.push_back(p + sd.n * 1.6f + Vec3{0, 0, 7.0f});
    }
    if (park) {
      for (float a = 1.0f; a + 1.0f < side_len; a += 12.5f)
        addFence(fence, at(a, -0.5f), at(std::min(a + 11.0f, side_len - 1.0f), -0.5f), 1.2f);
      for (int t = 0; t < 4; ++t)
        addTree(tree, pose(at(uniform(rng, 4, side_len - 4), -uniform(rng, 4, 20)), 0), rng);
      for (int b = 0; b < 5; ++b)
        addBush(veg, pose(at(uniform(rng, 2, side_len - 2), -uniform(rng, 1.5f, 6)), 0),
                uniform(rng, 1.0f, 2.2f), rng);
    } else if (!plaza) {
      float a = 0.0f;
      while (a < side_len - 6.0f) {
        float w = std::min(uniform(rng, 10.0f, 18.0f), side_len - a);
        float d = uniform(rng, 10.0f, 16.0f), hgt = uniform(rng, 7.0f, 36.0f);
        static const Vec3 kFacades[6] = {{0.62f, 0.62f, 0.64f}, {0.8f, 0.72f, 0.55f},
                                         {0.62f, 0.33f, 0.25f}, {0.55f, 0.6f, 0.66f},
                                         {0.86f, 0.83f, 0.72f}, {0.4f, 0.39f, 0.4f}};
        Vec3 col = kFacades[rng() % 6] * uniform(rng, 0.85f, 1.1f);
        addBuilding(building, pose(at(a + w * 0.5f, -d * 0.5f - 0.3f), face_yaw), d, w, hgt, col);
        // Some buildings carry a billboard on the roof, facing the street.
        if (hgt < 20.0f && rng() % 6 == 0)
          addBillboard(billboard, pose(at(a + w * 0.5f, -2.0f) + Vec3{0, 0, hgt}, face_yaw),
                       {uniform(rng, 0.2f, 0.9f), uniform(rng, 0.2f, 0.9f), 0.3f});
        if (rng() % 3 == 0)
          addBush(veg, pose(at(a + w * 0.5f, 0.6f), 0), 1.0f, rng);  // planter by the door
        a += w;
      }
    } else {
      // Plaza: a billboard, trees in planters and a few barriers at a work site.
      if (s == 0) addBillboard(billboard, pose(at(side_len * 0.5f, -6.0f), face_yaw),
                               {uniform(rng, 0.2f, 0.9f), uniform(rng, 0.2f, 0.9f), 0.3f});
      for (float a = 8.0f; a < side_len; a += 16.0f) {
        addTree(tree, pose(at(a, -3.0f), 0), rng);
        addBush(veg, pose(at(a + 4.0f, -3.0f), 0), 1.2f, rng);
      }
    }
    // Sidewalk trees between lamps on some sides.
    if (rng() % 2)
      for (float a = 18.0f; a < side_len - 2.0f; a += 24.0f)
        addTree(tree, pose(at(a, in - out - 0.8f), 0), rng);
    // Signs near the corners, facing approaching traffic.
    if (rng() % 2) addTrafficSign(sign, pose(at(side_len - 1.0f, in - out - 0.5f), face_yaw + 1.57f),
                                  int(rng() % 3));
    // Street furniture: hydrant, trash cans, litter, café chairs, barriers.
    if (rng() % 2)
      addProp(kFireHydrant, meshes.find("firehydrant"), at(uniform(rng, 5, side_len - 5), 3.2f),
              face_yaw);
    float can_at = uniform(rng, 3, side_len - 3);
    addProp(kTrashCan, meshes.find("trashcan"), at(can_at, 0.6f), face_yaw);
    addTrash(trash, pose(at(can_at + 1.0f, 0.5f), 0), rng);
    if (rng() % 3 == 0) addTrash(trash, pose(at(uniform(rng, 2, side_len - 2), 3.3f), 0), rng);
    if (!park && rng() % 2) {
      // Two chairs facing each other along the sidewalk (a café).
      float a = uniform(rng, 6, side_len - 6);
      float along_yaw = std::atan2(sd.u.y, sd.u.x);
      chairs_.push_back(int(props_.size()));
      addProp(kChair, meshes.find("chair"), at(a - 0.6f, 1.0f), along_yaw);
      chairs_.push_back(int(props_.size()));
      addProp(kChair, meshes.find("chair"), at(a + 0.6f, 1.0f), along_yaw + kPi);
    }
    if (rng() % 5 == 0)
      for (int k = 0; k < 3; ++k)
        addBarrier(barrier, pose(at(uniform(rng, 4, side_len - 4) , 2.0f + k * 0.2f), face_yaw));
  }
  std::string name = "block_" + std::to_string(origin_i_ + i) + "_" + std::to_string(origin_j_ + j) + "_";
  Vec3 origin{o.x + B * 0.5f, o.y + B * 0.5f, 0};
  addChunk(name + "sidewalk", kSidewalk, std::move(sidewalk), origin, meshes);
  addChunk(name + "terrain", kTerrain, std::move(terrain), origin, meshes);
  addChunk(name + "building", kBuilding, std::move(building), origin, meshes);
  addChunk(name + "tree", kTree, std::move(tree), origin, meshes);
  addChunk(name + "vegetation", kVegetation, std::move(veg), origin, meshes);
  addChunk(name + "fence", kFence, std::move(fence), origin, meshes);
  addChunk(name + "infrastructure", kInfrastructure, std::move(infra), origin, meshes);
  addChunk(name + "billboard", kBillboard, std::move(billboard), origin, meshes);
  addChunk(name + "trafficsign", kTrafficSign, std::move(sign), origin, meshes);
  addChunk(name + "mobilebarrier", kMobileBarrier, std::move(barrier), origin, meshes);
  addChunk(name + "trash", kTrash, std::move(trash), origin, meshes);
}

}  // namespace world
}  // namespace viper
