#include "viper/ground_truth/boxes.h"

#include "../common/gl_matrices.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace viper {
namespace {

MeshRecord boxMesh(uint64_t key, Eigen::Vector3f lo, Eigen::Vector3f hi) {
  MeshRecord m;
  m.key = key;
  for (int i = 0; i < 8; ++i) {
    m.positions_xyz.push_back((i & 1) ? hi.x() : lo.x());
    m.positions_xyz.push_back((i & 2) ? hi.y() : lo.y());
    m.positions_xyz.push_back((i & 4) ? hi.z() : lo.z());
  }
  m.indices = {0, 1, 3, 0, 3, 2};  // the z = lo face (2 triangles)
  return m;
}

GlMatrix placed(float yaw_rad, float scale, Eigen::Vector3f t) {
  Eigen::Affine3f a = Eigen::Translation3f(t) * Eigen::AngleAxisf(yaw_rad, Eigen::Vector3f::UnitZ()) *
                      Eigen::Scaling(scale);
  return a.matrix();
}

using test::glPerspective;

TEST(MeshRegistry, BoundsAndArea) {
  MeshRegistry store;
  store.add({boxMesh(1, {0, 0, 0}, {2, 3, 4})});
  ASSERT_NE(store.bounds(1), nullptr);
  EXPECT_TRUE(store.bounds(1)->max.isApprox(Eigen::Vector3d(2, 3, 4)));
  EXPECT_DOUBLE_EQ(store.area(1), 6.0);  // the 2x3 face
  EXPECT_EQ(store.bounds(2), nullptr);
  EXPECT_EQ(store.find(2), nullptr);
}

TEST(ObjectBox, CornersAreTheWorldTransformedBoundsOfAllParts) {
  MeshRegistry store;
  store.add(boxMesh(1, {-2, -1, 0}, {2, 1, 1}));      // body
  store.add(boxMesh(2, {1.5f, 1, 0}, {2.5f, 1.2f, 0.6f}));  // a wheel sticking out at +y
  CaptureFrame f;
  const GlMatrix w = placed(0.5f, 1.5f, {10, -4, 0.25f});
  for (uint32_t i = 0; i < 2; ++i) {
    DrawRecord d;
    d.index = i;
    d.mesh_key = i + 1;
    d.matrix_flags = kHasWorld;
    d.world = w;
    f.draws.push_back(d);
  }
  FrameObject o;
  o.draws = {0, 1};
  o.world = w;
  BoxStatus status;
  const OrientedBox box = objectBox(f, o, store, &status);
  ASSERT_EQ(status, BoxStatus::kOk);
  const Eigen::Vector3d lo(-2, -1, 0), hi(2.5, 1.2, 1);
  const auto corners = box.corners();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d local((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
    const Eigen::Vector3d expected = (w.cast<double>() * local.homogeneous()).head<3>();
    EXPECT_LT((corners[i] - expected).norm(), 1e-5) << "corner " << i << ": " << corners[i].transpose()
                                                     << " vs " << expected.transpose();
  }
  EXPECT_TRUE(box.size.isApprox(Eigen::Vector3d(4.5, 2.2, 1) * 1.5, 1e-6));
}

// A kart as SuperTuxKart draws it: the body at the kart's world matrix, each wheel at a matrix of
// its own (turned, at the wheel's place), all labelled car; and a second kart far away.
TEST(AttachParts, WheelsWithMatricesOfTheirOwnJoinTheirKart) {
  MeshRegistry store;
  store.add(boxMesh(1, {-1, -0.5f, -0.4f}, {1, 0.5f, 0.4f}));        // body
  store.add(boxMesh(2, {-0.2f, -0.2f, -0.1f}, {0.2f, 0.2f, 0.1f}));   // wheel
  const GlMatrix kart = placed(0.7f, 1.0f, {5, 2, 0});
  const GlMatrix other = placed(0.0f, 1.0f, {30, 2, 0});
  CaptureFrame f;
  auto add = [&](uint64_t mesh, const GlMatrix& w) {
    DrawRecord d;
    d.index = static_cast<uint32_t>(f.draws.size());
    d.mesh_key = mesh;
    d.matrix_flags = kHasWorld;
    d.world = w;
    f.draws.push_back(d);
  };
  add(1, kart);
  for (float x : {-0.8f, 0.8f}) add(2, kart * placed(0.3f * x, 1.0f, {x, 0.5f, -0.35f}));  // two wheels
  add(1, other);
  add(2, other * placed(0.1f, 1.0f, {0.8f, -0.5f, -0.3f}));
  std::vector<FrameObject> objects;
  for (const DrawRecord& d : f.draws) {
    FrameObject o;
    o.draws = {d.index};
    o.mesh_keys = {d.mesh_key};
    o.world = d.world;
    o.class_id = 24;
    o.is_thing = true;
    objects.push_back(o);
  }
  FrameObject person = objects[1];  // a person at a wheel's place is not the kart's
  person.class_id = 20;
  person.draws = {0};
  attachParts(objects, f, store);
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0].draws, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(objects[0].world, kart);
  EXPECT_EQ(objects[1].draws, (std::vector<uint32_t>{3, 4}));
  // The box takes the wheels where they are (they stick out below the body by 0.05).
  BoxStatus status;
  const OrientedBox box = objectBox(f, objects[0], store, &status);
  ASSERT_EQ(status, BoxStatus::kOk);
  EXPECT_NEAR(box.size.z(), 0.8 + 0.05, 1e-5);

  std::vector<FrameObject> mixed = {objects[0], person};
  attachParts(mixed, f, store);
  EXPECT_EQ(mixed.size(), 2u) << "another class is never attached";
}

TEST(ObjectBox, DeformedPartsComeBackThroughTheInverseMatrices) {
  CaptureFrame f;
  DrawRecord d;
  d.matrix_flags = kHasWorld | kHasView | kHasProjection;
  d.world = placed(-0.3f, 1.0f, {3, 2, 0});
  Eigen::Affine3f view = Eigen::Affine3f(Eigen::AngleAxisf(-1.2f, Eigen::Vector3f::UnitX())) *
                         Eigen::Translation3f(0, 0, -1.7f);
  d.view = view.matrix();
  d.projection = glPerspective(1.0, 1.5, 0.1, 200);
  const std::vector<Eigen::Vector3f> bent = {{0, 0, 0}, {0.2f, 0, 1}, {0.5f, 0.1f, 1.8f}, {-0.1f, 0.3f, 1.2f}};
  for (const auto& p : bent) {
    const Eigen::Vector4f c = d.projection * d.view * d.world * p.homogeneous();
    d.deformed_clip_xyzw.insert(d.deformed_clip_xyzw.end(), {c.x(), c.y(), c.z(), c.w()});
  }
  f.draws.push_back(d);
  FrameObject o;
  o.draws = {0};
  o.world = d.world;
  BoxStatus status;
  const OrientedBox box = objectBox(f, o, MeshRegistry(), &status);
  ASSERT_EQ(status, BoxStatus::kOk);
  EXPECT_TRUE(box.size.isApprox(Eigen::Vector3d(0.6, 0.3, 1.8), 1e-4)) << box.size.transpose();
}

TEST(ObjectBox, MissingMeshAndSingularMatrixAreReported) {
  CaptureFrame f;
  DrawRecord d;
  d.mesh_key = 42;
  d.matrix_flags = kHasWorld;
  f.draws.push_back(d);
  FrameObject o;
  o.draws = {0};
  BoxStatus status;
  objectBox(f, o, MeshRegistry(), &status);
  EXPECT_EQ(status, BoxStatus::kMissingMesh);
  o.world = GlMatrix::Zero();
  objectBox(f, o, MeshRegistry(), &status);
  EXPECT_EQ(status, BoxStatus::kSingularMatrix);
  o.world(0, 0) = std::numeric_limits<float>::quiet_NaN();
  objectBox(f, o, MeshRegistry(), &status);
  EXPECT_EQ(status, BoxStatus::kSingularMatrix);
}

TEST(OrientedBox, TransformedIntoAnotherFrameMovesTheCorners) {
  OrientedBox b;
  b.center = {1, 2, 3};
  b.size = {2, 1, 0.5};
  b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()));
  Eigen::Isometry3d T = Eigen::Translation3d(-1, 0, 5) * Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 1, 0).normalized());
  const auto before = b.corners();
  const auto after = b.transformed(T).corners();
  for (int i = 0; i < 8; ++i) EXPECT_LT((T * before[i] - after[i]).norm(), 1e-12);
}

}  // namespace
}  // namespace viper
