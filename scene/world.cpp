#include "world.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace viper {
namespace scene {
namespace {

using Eigen::Matrix4f;
using Eigen::Vector3f;

enum ObjectId : uint32_t { kTerrain = 1, kRoad, kBuilding1, kBuilding2, kCrate, kCarA, kCarB, kPerson, kRain };

// VIPER class ids (config/viper_classes.csv).
constexpr uint32_t kClassUnlabeled = 0, kClassRoad = 3, kClassTerrain = 6, kClassBuilding = 9, kClassTrashcan = 19,
                   kClassPerson = 20, kClassCar = 24;

constexpr double kRoadHalfLength = 60.0;

Matrix4f translation(float x, float y, float z) {
  return Eigen::Affine3f(Eigen::Translation3f(x, y, z)).matrix();
}
Matrix4f rotationZ(double a) { return Eigen::Affine3f(Eigen::AngleAxisf(float(a), Vector3f::UnitZ())).matrix(); }
Matrix4f rotationY(double a) { return Eigen::Affine3f(Eigen::AngleAxisf(float(a), Vector3f::UnitY())).matrix(); }
Matrix4f scaling(float x, float y, float z) { return Eigen::Affine3f(Eigen::Scaling(x, y, z)).matrix(); }

// Rotation `r` about the point (0, 0, z).
Matrix4f aboutHeight(float z, const Matrix4f& r) { return translation(0, 0, z) * r * translation(0, 0, -z); }

double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Position along the road, wrapping from one end to the other.
double wrapRoad(double x) {
  const double length = 2 * kRoadHalfLength;
  return x - length * std::floor((x + kRoadHalfLength) / length);
}

}  // namespace

Eigen::Matrix4f perspective(double fovy_rad, double aspect, double near_m, double far_m) {
  const double f = 1.0 / std::tan(fovy_rad / 2);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = -(far_m + near_m) / (far_m - near_m);
  p(2, 3) = -2 * far_m * near_m / (far_m - near_m);
  p(3, 2) = -1;
  return p.cast<float>();
}

Eigen::Matrix4f viewFromBodyPose(const Eigen::Matrix4d& map_from_body) {
  // Columns: body x (forward) -> GL -z, body y (left) -> GL -x, body z (up) -> GL +y.
  Eigen::Matrix4d gl_from_body = Eigen::Matrix4d::Identity();
  gl_from_body.topLeftCorner<3, 3>() << 0, -1, 0,
                                        0, 0, 1,
                                        -1, 0, 0;
  Eigen::Isometry3d pose(map_from_body);
  return (gl_from_body * pose.inverse().matrix()).cast<float>();
}

World::World(uint64_t seed, double aspect) : aspect_(aspect) {
  std::mt19937_64 rng(seed);
  building_height_[0] = static_cast<float>(8 + 6 * unit(rng));
  building_height_[1] = static_cast<float>(10 + 8 * unit(rng));
  car_phase_[0] = 10 * unit(rng);
  car_phase_[1] = 10 * unit(rng);
  const uint64_t rain_seed = rng();

  terrain_ = addMesh(makeGrid("terrain", 200, 200, 0, 8));
  road_ = addMesh(makeGrid("road", float(kRoadHalfLength), 4, 0, 1));
  box_ = addMesh(makeBox("unit_box", {0, 0, 0.5f}, {1, 1, 1}));
  // The crate has a mesh of its own: a mesh shared by objects of different classes could not be
  // labelled per resource (the buildings share theirs; the cars share all of theirs).
  crate_ = addMesh(makeBox("crate_box", {0, 0, 0.45f}, {0.9f, 0.9f, 0.9f}));
  // The car's model frame: x forward, y left, z up, origin on the ground under its centre.
  car_body_ = addMesh(makeBox("car_body", {0, 0, 0.7f}, {4.2f, 1.8f, 0.8f}));
  car_cabin_ = addMesh(makeBox("car_cabin", {-0.3f, 0, 1.4f}, {2.2f, 1.6f, 0.6f}));
  const char* wheel_names[4] = {"car_wheel_fl", "car_wheel_fr", "car_wheel_rl", "car_wheel_rr"};
  for (int w = 0; w < 4; ++w)
    wheels_[w] = addMesh(makeWheel(wheel_names[w], {w < 2 ? 1.35f : -1.35f, w % 2 == 0 ? 0.95f : -0.95f, 0.36f},
                                   0.36f, 0.25f, 20));
  tube_ = addMesh(makeSkinnedTube("person_tube", 0.22f, 1.8f, kBoneCount, 0.15f, 16, 18));
  rain_ = addMesh(makeRainStreaks("rain_streaks", rain_seed, 90, {-14, -10, 0}, {14, 10, 16},
                                  Vector3f(-1, -0.8f, 0).normalized()));
}

size_t World::addMesh(MeshData mesh) {
  meshes_.push_back(std::move(mesh));
  return meshes_.size() - 1;
}

void World::addCar(std::vector<DrawItem>& draws, uint32_t id, const Matrix4f& world, const Vector3f& color) const {
  // All parts of a car share its one world matrix; the parts' offsets live in the meshes.
  draws.push_back({id, kClassCar, "body", car_body_, ProgramKind::kLit, world, color, {}});
  draws.push_back({id, kClassCar, "cabin", car_cabin_, ProgramKind::kLit, world, {0.2f, 0.25f, 0.3f}, {}});
  const char* parts[4] = {"wheel_fl", "wheel_fr", "wheel_rl", "wheel_rr"};
  for (int w = 0; w < 4; ++w)
    draws.push_back({id, kClassCar, parts[w], wheels_[w], ProgramKind::kLit, world, {0.06f, 0.06f, 0.06f}, {}});
}

FrameState World::frame(double t) const {
  FrameState s;
  s.time_s = t;

  // Camera: drifts along the street, looking at a point that moves with it.
  const Eigen::Vector3d eye(-20 + 1.2 * t, -13 + 0.5 * std::sin(0.3 * t), 5.5 + 0.4 * std::sin(0.5 * t));
  const Eigen::Vector3d target(0.8 * t, 3, 1);
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(forward).normalized();
  s.map_from_camera_body.topLeftCorner<3, 3>() << forward, left, forward.cross(left);
  s.map_from_camera_body.topRightCorner<3, 1>() = eye;
  s.view = viewFromBodyPose(s.map_from_camera_body);
  s.projection = perspective(55.0 * M_PI / 180.0, aspect_, 0.1, 500.0);

  auto& d = s.draws;
  // The road sits 5 cm above the terrain: its own object, its own world matrix.
  d.push_back({kTerrain, kClassTerrain, "ground", terrain_, ProgramKind::kLit, Matrix4f::Identity(),
               {0.33f, 0.52f, 0.28f}, {}});
  d.push_back({kRoad, kClassRoad, "surface", road_, ProgramKind::kLit, translation(0, 0, 0.05f),
               {0.3f, 0.3f, 0.32f}, {}});
  // One box mesh, two buildings; the turning crate has its own.
  d.push_back({kBuilding1, kClassBuilding, "block", box_, ProgramKind::kLit,
               translation(10, 13, 0) * rotationZ(0.1) * scaling(8, 6, building_height_[0]), {0.72f, 0.66f, 0.58f}, {}});
  d.push_back({kBuilding2, kClassBuilding, "block", box_, ProgramKind::kLit,
               translation(-9, 14, 0) * scaling(7, 7, building_height_[1]), {0.58f, 0.6f, 0.7f}, {}});
  d.push_back({kCrate, kClassTrashcan, "crate", crate_, ProgramKind::kLit,
               translation(3, 6.5f, 0) * rotationZ(0.8 * t) * scaling(1.2f, 1.2f, 1.2f), {0.62f, 0.45f, 0.22f}, {}});
  // Two cars in opposite lanes, sharing every mesh.
  const double xa = wrapRoad(-12 + car_phase_[0] + 6.0 * t);
  const double xb = wrapRoad(16 + car_phase_[1] - 5.0 * t);
  addCar(d, kCarA, translation(float(xa), -2, 0), {0.78f, 0.1f, 0.1f});
  addCar(d, kCarB, translation(float(xb), 2, 0) * rotationZ(M_PI), {0.15f, 0.25f, 0.72f});
  // Skinned person: turns on the spot and bends at two joints.
  DrawItem person{kPerson, kClassPerson, "body", tube_, ProgramKind::kSkinned,
                  translation(-7, -5.5f, 0) * rotationZ(0.5 * t), {0.9f, 0.7f, 0.55f}, {}};
  const float joint = 1.8f / kBoneCount;
  const Matrix4f b0 = rotationY(0.12 * std::sin(1.5 * t));
  const Matrix4f b1 = b0 * aboutHeight(joint, rotationY(0.45 * std::sin(2.0 * t)));
  const Matrix4f b2 = b1 * aboutHeight(2 * joint, rotationY(0.7 * std::sin(2.0 * t + 0.8)));
  person.bones = {b0, b1, b2};
  d.push_back(person);
  // Rain last: blended, no depth writes. Falls 6 m/s and wraps every 8 m; the 0.5 m offset keeps
  // its world matrix from ever equalling the terrain's identity (equal matrices mean one object).
  d.push_back({kRain, kClassUnlabeled, "streaks", rain_, ProgramKind::kRain,
               translation(0, 0, -0.5f - float(std::fmod(6.0 * t, 8.0))), Vector3f::Ones(), {}});
  return s;
}

}  // namespace scene
}  // namespace viper
