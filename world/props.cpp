#include "props.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * float(rng() % 100000u) / 100000.0f;
}
const Vec3 kMetal{0.35f, 0.36f, 0.38f};
}  // namespace

void addStreetLamp(MeshData& m, const Mat4& at) {
  m.addCylinder(at, 0.12f, 7.2f, 6, kMetal, 0.08f);
  m.addBox(at * translation({0.8f, 0, 7.15f}), {0.9f, 0.05f, 0.05f}, kMetal);
  m.addBox(at * translation({1.6f, 0, 7.05f}), {0.35f, 0.18f, 0.08f}, {0.9f, 0.88f, 0.75f});
}

void addTree(MeshData& m, const Mat4& at, std::mt19937& rng) {
  float h = uniform(rng, 4.0f, 8.0f);
  m.addCylinder(at, 0.18f, h * 0.6f, 6, {0.35f, 0.25f, 0.15f}, 0.12f);
  Vec3 green{uniform(rng, 0.15f, 0.3f), uniform(rng, 0.4f, 0.55f), uniform(rng, 0.1f, 0.2f)};
  int blobs = 1 + int(rng() % 3);
  for (int b = 0; b < blobs; ++b) {
    float r = h * uniform(rng, 0.22f, 0.32f);
    Vec3 off{uniform(rng, -0.6f, 0.6f), uniform(rng, -0.6f, 0.6f), h * 0.65f + b * 0.8f};
    m.addSphere(at * translation(off), {r, r, r * 1.1f}, 8, 5, green);
  }
}

void addBush(MeshData& m, const Mat4& at, float size, std::mt19937& rng) {
  Vec3 green{uniform(rng, 0.1f, 0.25f), uniform(rng, 0.35f, 0.5f), 0.12f};
  m.addSphere(at * translation({0, 0, size * 0.3f}), {size * 0.5f, size * 0.5f, size * 0.4f}, 6, 4,
              green);
}

void addFence(MeshData& m, Vec3 a, Vec3 b, float height) {
  Vec3 d = b - a;
  float len = length(d);
  if (len < 0.1f) return;
  float yaw = std::atan2(d.y, d.x);
  Mat4 base = pose(a, yaw);
  Vec3 color{0.45f, 0.42f, 0.38f};
  int posts = std::max(1, int(len / 2.0f));
  for (int i = 0; i <= posts; ++i)
    m.addBox(base * translation({len * i / posts, 0, height * 0.5f}), {0.05f, 0.05f, height * 0.5f},
             color);
  for (float z : {height * 0.35f, height * 0.85f})
    m.addBox(base * translation({len * 0.5f, 0, z}), {len * 0.5f, 0.03f, 0.05f}, color);
}

void addBillboard(MeshData& m, const Mat4& at, Vec3 board_color) {
  for (float y : {-2.5f, 2.5f}) m.addCylinder(at * translation({0, y, 0}), 0.15f, 4.0f, 6, kMetal);
  m.addBox(at * translation({0.1f, 0, 5.5f}), {0.15f, 4.0f, 1.6f}, {0.2f, 0.2f, 0.22f});
  m.addBox(at * translation({0.27f, 0, 5.5f}), {0.02f, 3.8f, 1.45f}, board_color);
  m.addBox(at * translation({0.3f, -1.0f, 5.8f}), {0.02f, 1.6f, 0.45f},
           Vec3{1, 1, 1} - board_color * 0.7f);
}

void addTrafficSign(MeshData& m, const Mat4& at, int kind) {
  m.addCylinder(at, 0.04f, 2.6f, 6, kMetal);
  Vec3 face = kind == 0 ? Vec3{0.8f, 0.1f, 0.1f} : kind == 1 ? Vec3{0.95f, 0.85f, 0.2f}
                                                             : Vec3{0.15f, 0.3f, 0.8f};
  Mat4 plate = at * translation({0.06f, 0, 2.6f}) * rotationY(kPi * 0.5f);
  if (kind == 0) {
    m.addCylinder(plate, 0.35f, 0.03f, 12, face);
  } else if (kind == 1) {
    m.addCylinder(plate, 0.45f, 0.03f, 3, face);
  } else {
    m.addBox(at * translation({0.06f, 0, 2.6f}), {0.02f, 0.35f, 0.35f}, face);
  }
}

void addBarrier(MeshData& m, const Mat4& at) {
  for (float y : {-0.9f, 0.9f}) m.addBox(at * translation({0, y, 0.5f}), {0.2f, 0.05f, 0.5f}, kMetal);
  for (int s = 0; s < 4; ++s)
    m.addBox(at * translation({0, -0.75f + 0.5f * s, 0.8f}), {0.04f, 0.25f, 0.12f},
             s % 2 ? Vec3{0.95f, 0.95f, 0.95f} : Vec3{0.95f, 0.25f, 0.1f});
}

void addTrash(MeshData& m, const Mat4& at, std::mt19937& rng) {
  if (rng() % 2) {
    m.addSphere(at * translation({0, 0, 0.3f}), {0.35f, 0.3f, 0.3f}, 6, 4, {0.08f, 0.08f, 0.1f});
  } else {
    for (int i = 0; i < 4; ++i)
      m.addBox(at * translation({uniform(rng, -0.6f, 0.6f), uniform(rng, -0.6f, 0.6f), 0.04f}) *
                   rotationZ(uniform(rng, 0, 3)),
               {0.15f, 0.1f, 0.04f}, {0.8f, 0.75f, 0.6f});
  }
}

void addBuilding(MeshData& m, const Mat4& at, float depth, float width, float height, Vec3 color) {
  m.addBox(at * translation({0, 0, height * 0.5f}), {depth * 0.5f, width * 0.5f, height * 0.5f},
           color);
  // Roof ledge and a rooftop box give silhouettes some variety.
  m.addBox(at * translation({0, 0, height + 0.2f}),
           {depth * 0.5f + 0.3f, width * 0.5f + 0.3f, 0.2f}, color * 0.7f);
  m.addBox(at * translation({-depth * 0.15f, width * 0.1f, height + 1.2f}),
           {depth * 0.15f, width * 0.15f, 1.0f}, {0.4f, 0.4f, 0.42f});
  // Ground-floor shop front (awning) on the street side.
  m.addBox(at * translation({depth * 0.5f + 0.6f, 0, 3.2f}), {0.6f, width * 0.4f, 0.08f},
           {0.6f, 0.2f, 0.15f});
}

MeshData fireHydrantMesh() {
  MeshData m;
  Vec3 red{0.8f, 0.12f, 0.1f};
  m.addCylinder(Mat4(), 0.14f, 0.6f, 10, red);
  m.addSphere(translation({0, 0, 0.6f}), {0.14f, 0.14f, 0.12f}, 10, 4, red);
  m.addCylinder(translation({0, 0, 0.35f}) * rotationX(kPi * 0.5f) * translation({0, 0, -0.22f}),
                0.06f, 0.44f, 8, {0.7f, 0.7f, 0.65f});
  return m;
}

MeshData chairMesh() {
  MeshData m;
  Vec3 wood{0.55f, 0.35f, 0.2f};
  m.addBox(translation({0, 0, 0.45f}), {0.22f, 0.22f, 0.03f}, wood);
  m.addBox(translation({-0.2f, 0, 0.72f}), {0.02f, 0.22f, 0.25f}, wood);
  for (float x : {-0.18f, 0.18f})
    for (float y : {-0.18f, 0.18f}) m.addBox(translation({x, y, 0.22f}), {0.02f, 0.02f, 0.22f}, wood);
  return m;
}

MeshData trashCanMesh() {
  MeshData m;
  Vec3 green{0.15f, 0.3f, 0.22f};
  m.addCylinder(Mat4(), 0.3f, 0.95f, 12, green, 0.33f);
  m.addCylinder(translation({0, 0, 0.95f}), 0.35f, 0.08f, 12, {0.2f, 0.2f, 0.2f});
  return m;
}

}  // namespace world
}  // namespace viper
