#include "viper/ground_truth/normals.h"

#include "rigid_flow_case.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

namespace viper {
namespace {

using namespace test;

// The rigid case's square as a mesh: two triangles in the object's z = 0 plane.
MeshRecord squareMesh() {
  MeshRecord m;
  m.key = 77;
  m.positions_xyz = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

struct NormalsCase {
  RigidCase c;
  MeshRegistry meshes;
  GroundTruthInput in;
  std::optional<FrameCamera> camera;
  NormalsCase() {
    meshes.add(squareMesh());
    for (size_t p = 0; p < c.a.pixelCount(); ++p) c.a.draws[0].visible_pixels += c.a.draw_ids[p] != 0;
    refresh();
  }
  // After a change of c.a.
  void refresh() {
    in.frame = c.a;
    in.draw_ids = c.a.draw_ids.data(), in.primitive_ids = c.a.primitive_ids.data(), in.depth_m = c.metres_a.data();
    camera = chooseFrameCamera(c.a);
  }
  // The square's normal in camera a's optical frame, towards the camera.
  Eigen::Vector3d truth() const {
    const Eigen::Vector3d world = Eigen::Affine3d(c.world_a.cast<double>()).linear().col(2).normalized();
    Eigen::Vector3d n = opticalFromGlCamera() * c.view_a.cast<double>().topLeftCorner<3, 3>() * world;
    const Eigen::Vector3d centre = opticalFromWorld(c.view_a) * Eigen::Vector3d(0, 0, 1);
    return n.dot(centre) > 0 ? -n : n;
  }
  std::vector<float> run(StepProblems& problems, NormalStats* stats = nullptr, bool* ok = nullptr) {
    std::vector<float> out(3 * c.a.pixelCount(), 123.0f);
    const bool done = NormalsStep().process(in, camera, meshes, out.data(), problems, stats);
    if (ok) *ok = done;
    return out;
  }
  size_t square() const {
    size_t n = 0;
    for (uint32_t id : c.a.draw_ids) n += id != 0;
    return n;
  }
};

// Worst angle (degrees) to `truth` over the square's pixels; the rest must be NaN.
double worstAngle(const NormalsCase& k, const std::vector<float>& out) {
  double worst = 0;
  for (size_t p = 0; p < k.c.a.pixelCount(); ++p) {
    const Eigen::Vector3d n(out[3 * p], out[3 * p + 1], out[3 * p + 2]);
    if (k.c.a.draw_ids[p] == 0) {
      EXPECT_TRUE(std::isnan(n.x()) && std::isnan(n.y()) && std::isnan(n.z())) << "pixel " << p;
      continue;
    }
    EXPECT_NEAR(n.norm(), 1.0, 1e-6);
    const Eigen::Vector3d t = k.truth();  // atan2: acos loses half the digits near 0
    worst = std::max(worst, std::atan2(n.cross(t).norm(), n.dot(t)) * 180 / M_PI);
  }
  return worst;
}

TEST(Normals, RigidSquareHasItsPlanesNormalInTheOpticalFrameTowardsTheCamera) {
  NormalsCase k;
  StepProblems problems;
  NormalStats stats;
  const std::vector<float> out = k.run(problems, &stats);
  EXPECT_TRUE(problems.empty());
  ASSERT_GT(k.square(), 500u);
  EXPECT_EQ(stats.with_normal, k.square());
  EXPECT_EQ(stats.no_surface, k.c.a.pixelCount() - k.square());
  EXPECT_LT(worstAngle(k, out), 1e-4);
  // The camera looks at the square's front: its normal points back, against the optical z axis.
  EXPECT_LT(k.truth().z(), -0.1);
}

// The same square as a deformed draw: its clip positions as a vertex shader would leave them.
TEST(Normals, DeformedSquareFromItsClipPositionsIsTheSame) {
  NormalsCase k;
  const Eigen::Matrix4d pvw = (k.c.proj.cast<double>() * k.c.view_a.cast<double>() * k.c.world_a.cast<double>());
  const MeshRecord m = squareMesh();
  for (size_t v = 0; v < 4; ++v) {
    const Eigen::Vector4d clip = pvw * Eigen::Vector4d(m.positions_xyz[3 * v], m.positions_xyz[3 * v + 1], 0, 1);
    for (int i = 0; i < 4; ++i) k.c.a.draws[0].deformed_clip_xyzw.push_back(static_cast<float>(clip[i]));
  }
  k.c.a.draws[0].world = GlMatrix::Identity();  // a skinned draw's world may be anything: unused
  k.refresh();
  StepProblems problems;
  const std::vector<float> out = k.run(problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_LT(worstAngle(k, out), 1e-3);
}

// The back of the square: the triangle's winding turned around gives the same normal (towards the
// camera), not its opposite.
TEST(Normals, WindingDoesNotTurnTheNormalAway) {
  NormalsCase k;
  MeshRecord m = squareMesh();
  m.indices = {0, 2, 1, 0, 3, 2};
  k.meshes.add(m);
  StepProblems problems;
  EXPECT_LT(worstAngle(k, k.run(problems)), 1e-4);
}

TEST(Normals, DrawWithoutMeshIsNamedAndLeftNaN) {
  NormalsCase k;
  k.meshes = MeshRegistry();
  StepProblems problems;
  NormalStats stats;
  bool ok = false;
  const std::vector<float> out = k.run(problems, &stats, &ok);
  EXPECT_TRUE(ok);
  EXPECT_EQ(stats.missing_mesh, k.square());
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].input, StepInput::kMeshStore);
  EXPECT_NE(problems[0].text.find("000000000000004d"), std::string::npos) << problems[0].text;
  for (float v : out) EXPECT_TRUE(std::isnan(v));
}

TEST(Normals, DeformedDrawWithoutItsPositionsIsNamedAndLeftNaN) {
  NormalsCase k;
  k.c.a.draws[0].deformed_clip_xyzw.assign(8, 1.0f);  // two vertices of four
  k.refresh();
  StepProblems problems;
  NormalStats stats;
  const std::vector<float> out = k.run(problems, &stats);
  EXPECT_EQ(stats.missing_deformed, k.square());
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(std::string(problems[0].kind), "deformed");
  EXPECT_NE(problems[0].text.find("2 positions for 4 vertices"), std::string::npos) << problems[0].text;
  for (float v : out) EXPECT_TRUE(std::isnan(v));
}

TEST(Normals, PrimitiveIdPastTheMeshIsNamedAndLeftNaN) {
  NormalsCase k;
  size_t changed = 0;
  for (size_t p = 0; p < k.c.a.pixelCount(); ++p)
    if (k.c.a.draw_ids[p] != 0 && p % 2 == 0) k.c.a.primitive_ids[p] = 2, ++changed;
  k.refresh();
  StepProblems problems;
  NormalStats stats;
  const std::vector<float> out = k.run(problems, &stats);
  EXPECT_EQ(stats.bad_primitive, changed);
  EXPECT_EQ(stats.with_normal, k.square() - changed);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].input, StepInput::kPrimitiveIds);
  for (size_t p = 0; p < k.c.a.pixelCount(); ++p)
    EXPECT_EQ(std::isnan(out[3 * p]), k.c.a.draw_ids[p] == 0 || k.c.a.primitive_ids[p] == 2) << p;
}

TEST(Normals, FrameWithoutDepthOrCameraOrWithIdsPastItsDrawsHasNone) {
  for (int kase = 0; kase < 3; ++kase) {
    NormalsCase k;
    if (kase == 0) k.in.depth_m = nullptr;
    if (kase == 1) k.camera.reset();
    if (kase == 2) k.c.a.draw_ids[5] = 2, k.refresh();
    StepProblems problems;
    bool ok = true;
    const std::vector<float> out = k.run(problems, nullptr, &ok);
    EXPECT_FALSE(ok) << kase;
    ASSERT_EQ(problems.size(), 1u) << kase;
    EXPECT_EQ(problems[0].input, kase == 0 ? StepInput::kDepth : kase == 1 ? StepInput::kDraws : StepInput::kDrawIds);
    for (float v : out) EXPECT_TRUE(std::isnan(v)) << kase;
  }
}

// Pixels of the square without depth (a far-plane background's) have no normal.
TEST(Normals, PixelsWithoutDepthAreNaN) {
  NormalsCase k;
  size_t cleared = 0;
  for (size_t p = 0; p < k.c.a.pixelCount(); ++p)
    if (k.c.a.draw_ids[p] != 0 && p % 3 == 0) k.c.metres_a[p] = std::numeric_limits<float>::quiet_NaN(), ++cleared;
  k.refresh();
  StepProblems problems;
  NormalStats stats;
  const std::vector<float> out = k.run(problems, &stats);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(stats.with_normal, k.square() - cleared);
  for (size_t p = 0; p < k.c.a.pixelCount(); ++p) EXPECT_EQ(std::isnan(out[3 * p]), !std::isfinite(k.c.metres_a[p]));
}

}  // namespace
}  // namespace viper
