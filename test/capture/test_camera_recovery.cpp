// Camera recovery: perspective cameras split back into view and projection, what is not one rejected
// with its reason, and frames whose draws pass only combined matrices resolved to worlds and a camera.
#include "viper/capture/camera_recovery.h"

#include "../common/gl_matrices.h"

#include <gtest/gtest.h>

#include <random>

using namespace viper;

namespace {

// Products of float32 matrices (what engines pass) split back within this, relative to the largest
// value of the matrix compared.
constexpr double kRoundTrip = 1e-5;

double relativeError(const GlMatrix& got, const GlMatrix& want) {
  return (got.cast<double>() - want.cast<double>()).cwiseAbs().maxCoeff() / want.cast<double>().cwiseAbs().maxCoeff();
}

double uniform(std::mt19937& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

// A rigid view, rotated at random, its translation within `reach` on each axis.
GlMatrix randomView(std::mt19937& rng, double reach) {
  std::normal_distribution<double> normal;
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  v.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  for (int i = 0; i < 3; ++i) v(i, 3) = uniform(rng, -reach, reach);
  return v.cast<float>();
}

// A world: a rigid placement within 100 m, scaled by 0.2 to 5 on each axis.
GlMatrix randomWorld(std::mt19937& rng) {
  const Eigen::Vector4f scale(uniform(rng, 0.2, 5), uniform(rng, 0.2, 5), uniform(rng, 0.2, 5), 1);
  return randomView(rng, 100) * scale.asDiagonal();
}

// gluPerspective, or with `off_centre` the glFrustum whose window is shifted: (r + l) / (r - l) and
// (t + b) / (t - b) in P(0, 2) and P(1, 2).
GlMatrix randomProjection(std::mt19937& rng, bool off_centre) {
  const double fovy = uniform(rng, 0.3, 1.8), aspect = uniform(rng, 0.5, 2.5), near = uniform(rng, 0.05, 1),
               far = uniform(rng, 50, 5000);
  GlMatrix p = test::glPerspective(fovy, aspect, near, far);
  if (off_centre) p(0, 2) = uniform(rng, -0.5, 0.5), p(1, 2) = uniform(rng, -0.5, 0.5);
  return p;
}

// The camera every frame test draws with: 60 m from the origin, looking at it.
const GlMatrix kView = test::glLookAt(Eigen::Vector3d(30, -50, 12), Eigen::Vector3d(0, 0, 0));
const GlMatrix kProjection = test::glPerspective(1.0, 16.0 / 9.0, 0.1, 1000);

// A draw at `world` that passes the matrices in `known`, computed in float as an engine does; the
// matrices it does not pass hold a value no camera gives, so that reading one shows.
DrawMatrices draw(uint8_t known, const GlMatrix& world, const GlMatrix& view = kView,
                  const GlMatrix& projection = kProjection) {
  const GlMatrix junk = GlMatrix::Constant(7.0f);
  DrawMatrices d;
  d.known = known;
  d.world = (known & kMatWorld) ? world : junk;
  d.view = (known & kMatView) ? view : junk;
  d.projection = (known & kMatProjection) ? projection : junk;
  d.model_view = (known & kMatModelView) ? GlMatrix(view * world) : junk;
  d.view_projection = (known & kMatViewProjection) ? GlMatrix(projection * view) : junk;
  d.model_view_projection = (known & kMatModelViewProjection) ? GlMatrix(projection * (view * world)) : junk;
  return d;
}

// The draw of a world-space mesh (terrain): W = I.
DrawMatrices terrain(uint8_t known, const GlMatrix& view = kView, const GlMatrix& projection = kProjection) {
  return draw(known | kMatWorldSpace, GlMatrix::Identity(), view, projection);
}

std::vector<GlMatrix> worlds(size_t n) {
  std::mt19937 rng(11);
  std::vector<GlMatrix> w;
  for (size_t i = 0; i < n; ++i) w.push_back(randomWorld(rng));
  return w;
}

constexpr uint8_t kResolved = kMatWorld | kMatView | kMatProjection;

}  // namespace

TEST(CameraRecovery, DecomposesRandomCamerasBack) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const GlMatrix view = randomView(rng, 50), projection = randomProjection(rng, trial % 2 == 1);
    const GlMatrix m = projection * view;
    // Any positive scale is the same camera.
    for (const float scale : {1.0f, 1e-3f, 7.5f, 300.0f}) {
      const CameraDecomposition c = decomposeViewProjection(scale * m);
      ASSERT_TRUE(c.ok) << "trial " << trial << " scale " << scale << ": " << c.why << "\n" << m;
      EXPECT_LT(relativeError(c.view, view), kRoundTrip) << "trial " << trial << " scale " << scale << "\n" << c.view;
      EXPECT_LT(relativeError(c.projection, projection), kRoundTrip)
          << "trial " << trial << " scale " << scale << "\n" << c.projection;
      EXPECT_LT(c.residual, kRoundTrip) << "trial " << trial;
      EXPECT_LT(c.skew, 1e-6) << "trial " << trial;
      EXPECT_EQ(c.projection(3, 2), -1.0f);
      const double det = c.view.topLeftCorner<3, 3>().cast<double>().determinant();
      EXPECT_NEAR(det, 1.0, 1e-6) << "trial " << trial;
    }
  }
}

TEST(CameraRecovery, AcceptsInfiniteAndReversedDepthProjections) {
  std::mt19937 rng(5);
  const GlMatrix view = randomView(rng, 20);
  GlMatrix infinite = test::glPerspective(1.2, 1.5, 0.2, 100);
  infinite(2, 2) = -1, infinite(2, 3) = -0.4f;  // far plane at infinity
  GlMatrix reversed = infinite;
  reversed(2, 2) = 0, reversed(2, 3) = 0.2f;  // depth 1 at the near plane, 0 at infinity
  for (const GlMatrix& projection : {infinite, reversed}) {
    const CameraDecomposition c = decomposeViewProjection(projection * view);
    ASSERT_TRUE(c.ok) << c.why << "\n" << projection;
    EXPECT_LT(relativeError(c.view, view), kRoundTrip);
    EXPECT_LT(relativeError(c.projection, projection), kRoundTrip) << c.projection;
  }
}

TEST(CameraRecovery, RejectsOrthographic) {
  std::mt19937 rng(7);
  GlMatrix ortho = GlMatrix::Identity();  // glOrtho(-4, 4, -3, 3, 1, 100)
  ortho(0, 0) = 0.25f, ortho(1, 1) = 1 / 3.0f, ortho(2, 2) = -2 / 99.0f, ortho(2, 3) = -101 / 99.0f;
  const CameraDecomposition c = decomposeViewProjection(ortho * randomView(rng, 30));
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.why, "orthographic projection: view and projection cannot be separated");
}

TEST(CameraRecovery, RejectsSingular) {
  std::mt19937 rng(9);
  const GlMatrix view = randomView(rng, 30), projection = randomProjection(rng, true);
  GlMatrix no_depth = projection, no_x = projection, x_is_y = projection;
  no_depth(2, 3) = 0;  // depth row along w's
  no_x.row(0).setZero();
  x_is_y.row(0) = 2 * x_is_y.row(1);
  for (const GlMatrix& p : {GlMatrix(GlMatrix::Zero()), no_depth, no_x, x_is_y}) {
    const CameraDecomposition c = decomposeViewProjection(p * view);
    EXPECT_FALSE(c.ok) << p;
    EXPECT_NE(c.why.find("singular matrix"), std::string::npos) << c.why << "\n" << p;
  }
}

TEST(CameraRecovery, RejectsValuesThatAreNotNumbers) {
  std::mt19937 rng(13);
  GlMatrix m = randomProjection(rng, false) * randomView(rng, 30);
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    GlMatrix broken = m;
    broken(1, 3) = bad;
    const CameraDecomposition c = decomposeViewProjection(broken);
    EXPECT_FALSE(c.ok);
    EXPECT_NE(c.why.find("not a number"), std::string::npos) << c.why;
  }
}

TEST(CameraRecovery, RejectsSkewAboveTheLimitOnly) {
  std::mt19937 rng(17);
  const GlMatrix view = randomView(rng, 30);
  GlMatrix skewed = randomProjection(rng, true), slight = skewed;
  skewed(0, 1) = 0.01f * skewed(0, 0);
  slight(0, 1) = 1e-4f * slight(0, 0);
  const CameraDecomposition rejected = decomposeViewProjection(skewed * view);
  EXPECT_FALSE(rejected.ok);
  EXPECT_NEAR(rejected.skew, 0.01, 1e-5);
  EXPECT_NE(rejected.why.find("skewed projection"), std::string::npos) << rejected.why;
  const CameraDecomposition accepted = decomposeViewProjection(slight * view);
  EXPECT_TRUE(accepted.ok) << accepted.why;
  EXPECT_NEAR(accepted.skew, 1e-4, 1e-6);
  EXPECT_LT(relativeError(accepted.projection, slight), kRoundTrip);
}

TEST(CameraRecovery, RejectsMirroredNegatedAndBehindTheCamera) {
  std::mt19937 rng(19);
  const GlMatrix view = randomView(rng, 30);
  // Direct3D's perspective (depth 0..1, looking down +z), as a column-vector matrix.
  const float n = 0.5f, f = 200.0f;
  GlMatrix left_handed = GlMatrix::Zero();
  left_handed(0, 0) = 1.2f, left_handed(1, 1) = 1.6f;
  left_handed(2, 2) = f / (f - n), left_handed(2, 3) = -n * f / (f - n);
  left_handed(3, 2) = 1;
  const CameraDecomposition mirrored = decomposeViewProjection(left_handed * view);
  EXPECT_FALSE(mirrored.ok);
  EXPECT_NE(mirrored.why.find("left-handed"), std::string::npos) << mirrored.why;

  const GlMatrix m = randomProjection(rng, false) * view;
  const CameraDecomposition negated = decomposeViewProjection(-m);
  EXPECT_FALSE(negated.ok);
  EXPECT_NE(negated.why.find("negative overall scale"), std::string::npos) << negated.why;

  const CameraDecomposition behind = decomposeViewProjection(test::glPerspective(1.0, 1.0, -1, -100) * view);
  EXPECT_FALSE(behind.ok);
  EXPECT_NE(behind.why.find("behind the camera"), std::string::npos) << behind.why;
}

TEST(CameraRecovery, RejectsObliqueNearPlane) {
  std::mt19937 rng(23);
  GlMatrix oblique = randomProjection(rng, false);
  oblique(2, 0) = 0.3f;  // a clip plane tilted against the image's x axis, as water reflections use
  const CameraDecomposition c = decomposeViewProjection(oblique * randomView(rng, 30));
  EXPECT_FALSE(c.ok);
  EXPECT_GT(c.residual, kMaxDecompositionResidual);
  EXPECT_NE(c.why.find("oblique near plane"), std::string::npos) << c.why;
}

TEST(CameraRecovery, ModelViewAndProjectionWithOneWorldSpaceDraw) {
  const std::vector<GlMatrix> w = worlds(5);
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : w) draws.push_back(draw(kMatModelView | kMatProjection, world));
  draws.push_back(terrain(kMatModelView | kMatProjection));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "view: model-view of world-space draws; projection: given");
  EXPECT_TRUE(r.view == kView) << r.view;
  EXPECT_TRUE(r.projection == kProjection) << r.projection;
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < w.size(); ++i) {
    EXPECT_EQ(draws[i].known & kResolved, kResolved) << "draw " << i;
    EXPECT_LT(relativeError(draws[i].world, w[i]), kRoundTrip) << "draw " << i << "\n" << draws[i].world;
    EXPECT_TRUE(draws[i].view == kView) << "draw " << i;
  }
  EXPECT_TRUE(draws.back().world == GlMatrix::Identity());
}

TEST(CameraRecovery, ModelViewProjectionOnlyWithWorldSpaceTerrain) {
  const std::vector<GlMatrix> w = worlds(6);
  std::vector<DrawMatrices> draws(3, terrain(kMatModelViewProjection));
  for (const GlMatrix& world : w) draws.push_back(draw(kMatModelViewProjection, world));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "decomposed model-view-projection of world-space draws");
  EXPECT_LT(relativeError(r.view, kView), kRoundTrip) << r.view;
  EXPECT_LT(relativeError(r.projection, kProjection), kRoundTrip) << r.projection;
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < w.size(); ++i) {
    const DrawMatrices& d = draws[3 + i];
    EXPECT_EQ(d.known & kResolved, kResolved) << "object " << i;
    EXPECT_LT(relativeError(d.world, w[i]), kRoundTrip) << "object " << i << "\n" << d.world << "\nwant\n" << w[i];
  }
}

TEST(CameraRecovery, ViewProjectionAndWorld) {
  const std::vector<GlMatrix> w = worlds(4);
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : w) draws.push_back(draw(kMatViewProjection | kMatWorld, world));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "decomposed view-projection");
  EXPECT_LT(relativeError(r.view, kView), kRoundTrip);
  EXPECT_LT(relativeError(r.projection, kProjection), kRoundTrip);
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < w.size(); ++i) {
    EXPECT_TRUE(draws[i].world == w[i]) << "draw " << i;
    EXPECT_TRUE(draws[i].view == r.view && draws[i].projection == r.projection) << "draw " << i;
  }
}

TEST(CameraRecovery, ProjectionAndViewProjection) {
  const std::vector<GlMatrix> w = worlds(4);
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : w)
    draws.push_back(draw(kMatProjection | kMatViewProjection | kMatModelViewProjection, world));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "view: projection⁻¹ · view-projection; projection: given");
  EXPECT_TRUE(r.projection == kProjection);
  EXPECT_LT(relativeError(r.view, kView), kRoundTrip) << r.view;
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < w.size(); ++i)
    EXPECT_LT(relativeError(draws[i].world, w[i]), kRoundTrip) << "draw " << i << "\n" << draws[i].world;
}

TEST(CameraRecovery, ProjectionFromModelViewProjectionAndModelView) {
  const std::vector<GlMatrix> w = worlds(3);
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : w) draws.push_back(draw(kMatModelView | kMatModelViewProjection, world));
  draws.push_back(terrain(kMatModelView));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "view: model-view of world-space draws; projection: model-view-projection · model-view⁻¹");
  EXPECT_LT(relativeError(r.projection, kProjection), kRoundTrip) << r.projection;
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < w.size(); ++i) EXPECT_LT(relativeError(draws[i].world, w[i]), kRoundTrip) << "draw " << i;
}

TEST(CameraRecovery, CountsDrawsOfAnotherCamera) {
  // A reflection pass's sky, drawn in world space from a mirrored camera, and a weapon drawn with its
  // own field of view, among terrain and objects of the frame's camera.
  const GlMatrix reflected = kView * Eigen::Vector4f(1, 1, -1, 1).asDiagonal();
  const GlMatrix weapon_projection = test::glPerspective(0.6, 16.0 / 9.0, 0.01, 10);
  const std::vector<GlMatrix> w = worlds(3);
  std::vector<DrawMatrices> draws(2, terrain(kMatModelView | kMatProjection));
  draws.push_back(terrain(kMatModelView | kMatProjection, reflected));
  for (const GlMatrix& world : w) draws.push_back(draw(kMatModelView | kMatProjection, world));
  draws.push_back(draw(kMatModelView | kMatProjection, w[0], kView, weapon_projection));
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_TRUE(r.view == kView);
  EXPECT_TRUE(r.projection == kProjection);
  EXPECT_EQ(r.inconsistent_draws, 2);
  const DrawMatrices& weapon = draws.back();
  EXPECT_TRUE(weapon.projection == weapon_projection);  // what a draw gave is kept
  EXPECT_LT(relativeError(weapon.world, w[0]), kRoundTrip);
}

TEST(CameraRecovery, MostCommonProjectionWinsTiesGoToTheFirst) {
  const GlMatrix other = test::glPerspective(0.6, 1.0, 0.5, 50);
  std::vector<DrawMatrices> draws = {terrain(kMatView | kMatProjection, kView, other),
                                     terrain(kMatView | kMatProjection), terrain(kMatView | kMatProjection)};
  FrameCameraResult r = resolveFrameMatrices(draws);
  EXPECT_TRUE(r.projection == kProjection);
  EXPECT_EQ(r.inconsistent_draws, 1);
  draws = {terrain(kMatView | kMatProjection, kView, other), terrain(kMatView | kMatProjection)};
  r = resolveFrameMatrices(draws);
  EXPECT_TRUE(r.projection == other);
}

TEST(CameraRecovery, NothingToGoOn) {
  std::vector<DrawMatrices> none;
  FrameCameraResult r = resolveFrameMatrices(none);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.why.find("no camera"), std::string::npos) << r.why;

  // Model-views alone: the view is never guessed from them (each is V · W, W unknown).
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : worlds(3)) draws.push_back(draw(kMatModelView, world));
  draws.push_back(draw(kMatModelView, GlMatrix::Identity()));
  r = resolveFrameMatrices(draws);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.known, 0);
  EXPECT_NE(r.why.find("no camera"), std::string::npos) << r.why;
  for (const DrawMatrices& d : draws) EXPECT_EQ(d.known, kMatModelView);

  // Projection found, view not: worlds stay unknown.
  draws.clear();
  for (const GlMatrix& world : worlds(3)) draws.push_back(draw(kMatModelView | kMatModelViewProjection, world));
  r = resolveFrameMatrices(draws);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.known, kMatProjection);
  EXPECT_EQ(r.why.rfind("no view", 0), 0u) << r.why;
  for (const DrawMatrices& d : draws) EXPECT_EQ(d.known & kResolved, kMatProjection);
}

TEST(CameraRecovery, OrthographicViewProjectionNeedsItsProjection) {
  GlMatrix ortho = GlMatrix::Identity();
  ortho(0, 0) = 0.1f, ortho(1, 1) = 0.1f, ortho(2, 2) = -0.01f;
  std::vector<DrawMatrices> draws = {draw(kMatViewProjection | kMatWorld, GlMatrix::Identity(), kView, ortho)};
  FrameCameraResult r = resolveFrameMatrices(draws);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.why, "decomposed view-projection: orthographic projection: view and projection cannot be separated");

  draws = {draw(kMatViewProjection | kMatProjection | kMatWorld, GlMatrix::Identity(), kView, ortho)};
  r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_LT(relativeError(r.view, kView), kRoundTrip) << r.view;
}

TEST(CameraRecovery, SeparateMatricesPassThroughUnchanged) {
  const std::vector<GlMatrix> w = worlds(4);
  std::vector<DrawMatrices> draws;
  for (const GlMatrix& world : w) draws.push_back(draw(kResolved, world));
  const std::vector<DrawMatrices> before = draws;
  const FrameCameraResult r = resolveFrameMatrices(draws);
  ASSERT_TRUE(r.ok) << r.why;
  EXPECT_EQ(r.source, "view and projection");
  EXPECT_EQ(r.inconsistent_draws, 0);
  for (size_t i = 0; i < draws.size(); ++i) {
    EXPECT_EQ(draws[i].known, before[i].known);
    EXPECT_TRUE(draws[i].world == before[i].world && draws[i].view == before[i].view &&
                draws[i].projection == before[i].projection)
        << "draw " << i;
  }
}
