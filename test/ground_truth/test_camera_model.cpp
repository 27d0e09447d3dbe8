// Camera model: intrinsics and depth from OpenGL matrices, checked against the OpenGL pipeline
// itself (clip -> NDC -> window transform as the GL specification defines it).
#include "viper/ground_truth/camera_model.h"

#include "../common/gl_matrices.h"
#include "../common/vector_paths.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace viper {
namespace {

// glFrustum(l, r, b, t, n, f).
GlMatrix glFrustum(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * n / (r - l);
  m(0, 2) = (r + l) / (r - l);
  m(1, 1) = 2 * n / (t - b);
  m(1, 2) = (t + b) / (t - b);
  m(2, 2) = -(f + n) / (f - n);
  m(2, 3) = -2 * f * n / (f - n);
  m(3, 2) = -1;
  return m.cast<float>();
}

GlMatrix glOrtho(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2 / (r - l);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 1) = 2 / (t - b);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 2) = -2 / (f - n);
  m(2, 3) = -(f + n) / (f - n);
  return m.cast<float>();
}

using test::glLookAt;  // Z up
using test::glPerspective;

struct GlWindowPoint {
  double x, y;   // window coordinates, origin at the bottom-left corner of the bottom-left pixel
  double depth;  // window depth in [0, 1]
};

// The OpenGL fixed-function path: clip = P * eye, NDC = clip / w, viewport (0, 0, W, H), depth range [0, 1].
GlWindowPoint glPipeline(const GlMatrix& projection, const Eigen::Vector3d& eye, int width, int height) {
  const Eigen::Vector4d clip = projection.cast<double>() * eye.homogeneous();
  const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
  return {(ndc.x() + 1) * width / 2, (ndc.y() + 1) * height / 2, (ndc.z() + 1) / 2};
}

// Pixel (col, row) with rows top-down: GL window pixel (col, height-1-row) has its center at
// (col + 0.5, height - 1 - row + 0.5), which ROS/OpenCV call (u, v) = (col, row).
Eigen::Vector2d rosPixelOf(const GlWindowPoint& w, int height) {
  return {w.x - 0.5, (height - w.y) - 0.5};
}

TEST(CameraModel, IntrinsicsAgreeWithGlPipeline) {
  const int width = 640, height = 360;
  const GlMatrix projections[] = {
      glPerspective(60.0 * M_PI / 180, double(width) / height, 0.1, 500.0),
      glFrustum(-0.07, 0.13, -0.04, 0.08, 0.1, 100.0),  // off-center: principal point away from the middle
      glPerspective(90.0 * M_PI / 180, 1.0, 0.5, 50.0) * 3.0f,  // scaled matrix: same picture
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-3.0, 3.0), z(-60.0, -0.6);
  for (const GlMatrix& p : projections) {
    const PinholeIntrinsics k = intrinsicsFromGlProjection(p, width, height);
    EXPECT_EQ(k.width, uint32_t(width));
    EXPECT_EQ(k.height, uint32_t(height));
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d eye(xy(rng), xy(rng), z(rng));
      const Eigen::Vector2d gl = rosPixelOf(glPipeline(p, eye, width, height), height);
      const Eigen::Vector2d ros = k.project(opticalFromGlCamera() * eye);
      EXPECT_NEAR(gl.x(), ros.x(), 1e-4) << "eye point " << eye.transpose() << "\nP =\n" << p;
      EXPECT_NEAR(gl.y(), ros.y(), 1e-4) << "eye point " << eye.transpose() << "\nP =\n" << p;
    }
  }
}

TEST(CameraModel, CenteredProjectionPutsPrincipalPointBetweenCenterPixels) {
  // Symmetric frustum: the optical axis pierces the image exactly between the middle pixels.
  const PinholeIntrinsics k = intrinsicsFromGlProjection(glPerspective(M_PI / 2, 2.0, 0.1, 10.0), 640, 320);
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  EXPECT_DOUBLE_EQ(k.cy, 159.5);
  // 90 degrees vertical field of view: fy = (H/2) / tan(45 deg).
  EXPECT_NEAR(k.fy, 160.0, 1e-4);
  EXPECT_NEAR(k.fx, 160.0, 1e-4);
  EXPECT_NEAR(k.skew, 0.0, 1e-12);
}

TEST(CameraModel, ViewProjectionSplitsBackIntoViewAndProjection) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    // A random rigid view and an off-centre frustum, OpenGL's (row 3 = (0, 0, -1, 0)) or a
    // left-handed one (row 3 = (0, 0, 1, 0), Irrlicht), scaled as programs sometimes pass them.
    Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
    V.topLeftCorner<3, 3>() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    V.topRightCorner<3, 1>() = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 50.0;
    Eigen::Matrix4d P = glFrustum(-0.6 + 0.1 * u(rng), 0.5, -0.3, 0.4 + 0.1 * u(rng), 0.3, 900).cast<double>();
    if (trial % 2) P.col(2) = -P.col(2);  // z flipped: a left-handed projection
    const GlMatrix vp = (P * V).cast<float>();
    GlMatrix view, projection;
    ASSERT_TRUE(decomposeViewProjection(vp, view, projection)) << "trial " << trial;
    EXPECT_LT((view.cast<double>() - V).cwiseAbs().maxCoeff(), 1e-3) << "trial " << trial << "\n" << view;
    EXPECT_LT(((projection.cast<double>() - P).cwiseAbs().array() / (P.cwiseAbs().array() + 1.0)).maxCoeff(), 1e-4)
        << "trial " << trial << "\n" << projection;
    const float det = view.topLeftCorner<3, 3>().determinant();
    EXPECT_NEAR(det, 1.0f, 1e-4f);
  }
  // Not of that form: orthographic, and skewed.
  GlMatrix view, projection;
  EXPECT_FALSE(decomposeViewProjection(GlMatrix::Identity(), view, projection));
  Eigen::Matrix4d skew = glFrustum(-1, 1, -1, 1, 1, 100).cast<double>();
  skew(0, 1) = 0.3;
  EXPECT_FALSE(decomposeViewProjection(skew.cast<float>(), view, projection));
}

TEST(CameraModel, RejectsNonPerspectiveMatrices) {
  EXPECT_THROW(intrinsicsFromGlProjection(GlMatrix::Identity(), 64, 64), std::invalid_argument);
  EXPECT_THROW(intrinsicsFromGlProjection(glOrtho(-1, 1, -1, 1, 0.1, 10), 64, 64), std::invalid_argument);
  EXPECT_THROW(intrinsicsFromGlProjection(glPerspective(1.0, 1.0, 0.1, 10), 0, 64), std::invalid_argument);
  GlMatrix nan_matrix = glPerspective(1.0, 1.0, 0.1, 10);
  nan_matrix(0, 0) = NAN;
  EXPECT_THROW(intrinsicsFromGlProjection(nan_matrix, 64, 64), std::invalid_argument);
}

TEST(CameraModel, DepthOfPointsAtKnownDistance) {
  const GlMatrix projections[] = {glPerspective(1.0, 1.5, 0.5, 200.0),
                                  glFrustum(-0.2, 0.3, -0.1, 0.2, 0.25, 1000.0)};
  for (const GlMatrix& p : projections) {
    const DepthLinearizer lin(p);
    for (double depth_m : {0.6, 1.0, 2.5, 7.0, 19.0, 55.0, 120.0}) {
      // Off-axis points too: depth is along the optical axis, not the ray length.
      const Eigen::Vector3d eye(0.3 * depth_m, -0.2 * depth_m, -depth_m);
      const float window = static_cast<float>(glPipeline(p, eye, 100, 100).depth);
      EXPECT_NEAR(lin.toMetres(window), depth_m, 1e-4 * depth_m) << "window depth " << window << "\nP =\n" << p;
    }
  }
}

TEST(CameraModel, DepthOrthographic) {
  const GlMatrix p = glOrtho(-4, 4, -3, 3, 1.0, 21.0);
  const DepthLinearizer lin(p);
  for (double depth_m : {1.5, 6.0, 20.0}) {
    const float window = static_cast<float>(glPipeline(p, Eigen::Vector3d(1.0, 2.0, -depth_m), 8, 6).depth);
    EXPECT_NEAR(lin.toMetres(window), depth_m, 1e-5 * 21.0);
  }
}

TEST(CameraModel, DepthIsNaNWithoutSurface) {
  const DepthLinearizer lin(glPerspective(1.0, 1.0, 0.1, 100.0));
  EXPECT_TRUE(std::isnan(lin.toMetres(1.0f)));
  EXPECT_TRUE(std::isnan(lin.toMetres(1.5f)));
  EXPECT_TRUE(std::isnan(lin.toMetres(-0.1f)));
  EXPECT_TRUE(std::isnan(lin.toMetres(NAN)));
  EXPECT_NEAR(lin.toMetres(0.0f), 0.1, 1e-6);  // the near plane
  // A degenerate matrix must not produce a finite depth.
  EXPECT_TRUE(std::isnan(DepthLinearizer(GlMatrix::Zero()).toMetres(0.5f)));
}

// A distance that is positive and finite in double but rounds to 0 or to infinity as the float
// published has no depth either, on every path (the vector kernels check the floats).
TEST(CameraModel, DepthNoFloatHoldsIsNaN) {
  for (const auto& [p23, p22] : {std::pair<float, float>{3e38f, 1e-3f}, {1e-30f, 1e30f}}) {
    GlMatrix p = GlMatrix::Zero();
    p(2, 3) = p23, p(2, 2) = p22;
    EXPECT_TRUE(std::isnan(DepthLinearizer(p).toMetres(0.5f))) << p23 << " / " << p22;
    CaptureFrame f;
    f.width = 40, f.height = 1;
    DrawRecord d;
    d.matrix_flags = kHasProjection;
    d.projection = p;
    f.draws.push_back(d);
    f.draw_ids.assign(40, 1);
    f.depth_window.assign(40, 0.5f);
    std::vector<Instructions> paths = test::vectorPaths();
    paths.push_back(Instructions::kScalar);
    for (Instructions path : paths) {
      const std::vector<float> m = depthMetres(f, nullptr, path);
      EXPECT_EQ(std::count_if(m.begin(), m.end(), [](float x) { return std::isnan(x); }), 40)
          << test::pathName(path) << ", " << p23 << " / " << p22;
    }
  }
}

DrawRecord cameraDraw(uint32_t index, const GlMatrix& view, const GlMatrix& projection, uint32_t visible) {
  DrawRecord d;
  d.index = index;
  d.matrix_flags = kHasWorld | kHasView | kHasProjection;
  d.view = view;
  d.projection = projection;
  d.visible_pixels = visible;
  return d;
}

TEST(CameraModel, FrameCameraIsThePairWithMostVisiblePixels) {
  const GlMatrix p_main = glPerspective(1.0, 1.0, 0.1, 100.0);
  const GlMatrix p_sky = glPerspective(1.0, 1.0, 1.0, 5000.0);
  const GlMatrix view = glLookAt({0, 0, 2}, {1, 5, 2});
  CaptureFrame frame;
  // The sky draw alone is the largest draw, but the main pair wins over all its draws together.
  frame.draws.push_back(cameraDraw(0, view, p_sky, 500));
  frame.draws.push_back(cameraDraw(1, view, p_main, 300));
  frame.draws.push_back(cameraDraw(2, view, p_main, 300));
  DrawRecord hud;  // no camera matrices: never a candidate, however many pixels it has
  hud.index = 3;
  hud.matrix_flags = kHasProjection;
  hud.visible_pixels = 5000;
  frame.draws.push_back(hud);
  const auto camera = chooseFrameCamera(frame);
  ASSERT_TRUE(camera);
  EXPECT_EQ(camera->projection, p_main);
  EXPECT_EQ(camera->view, view);
  EXPECT_EQ(camera->visible_pixels, 600u);

  // Nothing visible: the first draw with both matrices.
  for (auto& d : frame.draws) d.visible_pixels = 0;
  EXPECT_EQ(chooseFrameCamera(frame)->projection, p_sky);

  frame.draws = {hud};
  EXPECT_FALSE(chooseFrameCamera(frame));
}

TEST(CameraModel, DepthImageUsesEachPixelsOwnDraw) {
  const GlMatrix p_main = glPerspective(1.0, 1.0, 0.1, 100.0);
  const GlMatrix p_sky = glPerspective(1.0, 1.0, 1.0, 5000.0);
  CaptureFrame frame;
  frame.width = 4;
  frame.height = 1;
  frame.draws.push_back(cameraDraw(0, GlMatrix::Identity(), p_main, 1));
  frame.draws.push_back(cameraDraw(1, GlMatrix::Identity(), p_sky, 1));
  DrawRecord no_matrices;
  no_matrices.index = 2;
  no_matrices.visible_pixels = 1;
  frame.draws.push_back(no_matrices);
  const auto window_of = [](const GlMatrix& p, double depth_m) {
    return static_cast<float>(glPipeline(p, Eigen::Vector3d(0, 0, -depth_m), 1, 1).depth);
  };
  frame.draw_ids = {1, 2, 3, 0};
  frame.depth_window = {window_of(p_main, 10.0), window_of(p_sky, 3000.0), window_of(p_main, 4.0), 1.0f};
  const FrameCamera camera{GlMatrix::Identity(), p_main, 1};
  const std::vector<float> depth = depthMetres(frame, &camera);
  ASSERT_EQ(depth.size(), 4u);
  EXPECT_NEAR(depth[0], 10.0, 1e-3);
  EXPECT_NEAR(depth[1], 3000.0, 3.0);  // far away with near = 1: float window depth limits precision
  EXPECT_NEAR(depth[2], 4.0, 1e-3);    // draw without matrices: the frame camera's projection
  EXPECT_TRUE(std::isnan(depth[3]));   // background

  // Without a frame camera the draw lacking matrices has no depth either.
  EXPECT_TRUE(std::isnan(depthMetres(frame, nullptr)[2]));
  EXPECT_NEAR(depthMetres(frame, nullptr)[0], 10.0, 1e-3);
}

// Random projections for the vector paths of the depth conversions: perspective and orthographic,
// arbitrary entries, and rows that make denominators 0 (P22 = P32 = 0 in depthMetres, or
// P32 z + P33 = 0 at 2 m in windowDepthFromMetres), or that hold a NaN or an infinity.
GlMatrix randomProjection(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<float> g(0.0f, 2.0f);
  GlMatrix p =
      glFrustum(-0.1 - u(rng), 0.1 + u(rng), -0.1 - u(rng), 0.1 + u(rng), 0.01 + u(rng), 10.0 + 1000.0 * u(rng));
  switch (rng() % 7) {
    case 0:
      p = glOrtho(-1, 1, -1, 1, -u(rng), 1 + 100 * u(rng));
      break;
    case 1:
      for (int i = 0; i < 16; ++i) p.data()[i] = g(rng);
      break;
    case 2:
      p(2, 2) = p(3, 2) = 0.0f;
      break;
    case 3:
      p(3, 2) = 1.0f, p(3, 3) = 2.0f;
      break;
    case 4:
      p(2 + rng() % 2, 2 + rng() % 2) = rng() % 2 ? std::numeric_limits<float>::quiet_NaN() : -INFINITY;
      break;
    default:
      break;
  }
  return p;
}

// One of the values `edge` or, half of the time, `usual`.
template <typename Usual>
float randomValue(std::mt19937& rng, const std::vector<float>& edge, Usual usual) {
  return rng() % 2 ? usual() : edge[rng() % edge.size()];
}

// A frame of n pixels (one row) with `draws` draws, some without a projection, one with an index
// out of range (depthMetres skips it), draw ids in runs (0, valid, out of range), and window depths
// of every kind.
CaptureFrame randomDepthFrame(std::mt19937& rng, size_t n, uint32_t draws) {
  CaptureFrame f;
  f.width = static_cast<uint32_t>(n), f.height = 1;
  for (uint32_t i = 0; i < draws; ++i) {
    DrawRecord d;
    d.index = i == 3 ? draws + 5 : i;
    d.matrix_flags = rng() % 3 ? kHasProjection | kHasView : 0;
    d.projection = randomProjection(rng);
    f.draws.push_back(d);
  }
  std::uniform_int_distribution<int> run(1, 40), long_run(100, 300);
  while (f.draw_ids.size() < n) {
    const uint32_t kind = rng() % 8;
    const uint32_t id = kind == 0   ? 0
                        : kind == 1 ? draws + 1 + rng() % 3
                        : kind == 2 ? 0xffffffffu - rng() % 2
                                    : 1 + rng() % std::max(draws, 1u);
    for (int r = rng() % 10 ? run(rng) : long_run(rng); r > 0 && f.draw_ids.size() < n; --r) f.draw_ids.push_back(id);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<float> edge = {0.0f, -0.0f, 1.0f, 1.5f, -0.25f, nan, -nan, inf, -inf, 0.75f, 0.5f,
                                   std::nextafter(1.0f, 0.0f), std::numeric_limits<float>::denorm_min(), 1e-30f};
  std::uniform_real_distribution<float> d(0.9f, 1.0f);
  for (size_t i = 0; i < n; ++i) f.depth_window.push_back(randomValue(rng, edge, [&] { return d(rng); }));
  return f;
}

std::vector<float> randomMetres(std::mt19937& rng, size_t n) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<float> edge = {0.0f, -0.0f, -5.0f, nan, -nan, inf, -inf, 1e38f, std::numeric_limits<float>::max(),
                                   std::numeric_limits<float>::denorm_min(), 2.0f, 1e-30f, 1e-3f};
  std::uniform_real_distribution<float> log10m(-2.0f, 3.5f);
  std::vector<float> m;
  for (size_t i = 0; i < n; ++i) m.push_back(randomValue(rng, edge, [&] { return std::pow(10.0f, log10m(rng)); }));
  return m;
}

// Every vector path of depthMetres and windowDepthFromMetres gives the scalar path's bits (NaNs
// included) and bad-depth count, at sizes around the blocks (8, 16 pixels).
TEST(CameraModel, DepthVectorPathsGiveTheScalarBits) {
  const std::vector<Instructions> paths = test::vectorPaths();
  if (paths.empty()) GTEST_SKIP() << "no vector path on this CPU";
  // Products of floats are exact in double, so that a fused multiply-add mostly rounds as the
  // scalar code does; not where a tiny window depth d makes z_ndc = 2 d - 1 a double of many bits
  // and P22 - z_ndc P32 cancels: there the depth would differ in float.
  {
    CaptureFrame f;
    f.width = 64, f.height = 1;
    DrawRecord d;
    d.matrix_flags = kHasProjection;
    d.projection = GlMatrix::Zero();
    d.projection(2, 2) = 1.1f, d.projection(3, 2) = -1.1f, d.projection(2, 3) = 1.0f;
    f.draws.push_back(d);
    f.draw_ids.assign(64, 1);
    for (int i = 0; i < 64; ++i) f.depth_window.push_back(std::ldexp(1.0f + i / 64.0f, -30 - i % 16));
    const std::vector<float> want = depthMetres(f, nullptr, Instructions::kScalar);
    EXPECT_GT(want[5], 1e9f);
    for (Instructions path : paths)
      EXPECT_EQ(test::firstDifference(want.data(), depthMetres(f, nullptr, path).data(), want.size()), -1)
          << "cancelling depth, " << test::pathName(path);
  }
  std::mt19937 rng(11);
  for (size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 31, 33, 63, 65, 1000, 1921 * 3 + 5}) {
    for (uint32_t draws : {0u, 1u, 6u, 300u}) {
      for (int trial = 0; trial < 3; ++trial) {
        CaptureFrame f = randomDepthFrame(rng, n, draws);
        const FrameCamera camera{GlMatrix::Identity(), randomProjection(rng), 1};
        const GlMatrix fallback = randomProjection(rng);
        const std::vector<float> random_m = randomMetres(rng, n);
        for (bool with_camera : {false, true}) {
          const FrameCamera* cam = with_camera ? &camera : nullptr;
          const std::vector<float> want = depthMetres(f, cam, Instructions::kScalar);
          std::vector<uint32_t> ids;
          std::swap(ids, f.draw_ids);
          const std::vector<float> want_no_ids = depthMetres(f, cam, Instructions::kScalar);
          std::swap(ids, f.draw_ids);
          for (Instructions path : paths) {
            const std::string what = std::string(test::pathName(path)) + " n " + std::to_string(n) + " draws " +
                                     std::to_string(draws) + " camera " + std::to_string(with_camera);
            const std::vector<float> got = depthMetres(f, cam, path);
            ASSERT_EQ(got.size(), want.size());
            EXPECT_EQ(test::firstDifference(want.data(), got.data(), n), -1) << "depthMetres " << what;
            std::swap(ids, f.draw_ids);
            const std::vector<float> got_no_ids = depthMetres(f, cam, path);
            std::swap(ids, f.draw_ids);
            EXPECT_EQ(test::firstDifference(want_no_ids.data(), got_no_ids.data(), n), -1)
                << "depthMetres without ids " << what;
          }
          // Back: from random depths, and from the depth just computed (as the ROS nodes do).
          for (const std::vector<float>* m : {&random_m, &want}) {
            const GlMatrix* fb = with_camera ? &fallback : nullptr;
            size_t want_bad = 0;
            const std::vector<float> want_w = windowDepthFromMetres(f, *m, fb, &want_bad, Instructions::kScalar);
            for (Instructions path : paths) {
              size_t got_bad = 0;
              const std::vector<float> got_w = windowDepthFromMetres(f, *m, fb, &got_bad, path);
              EXPECT_EQ(test::firstDifference(want_w.data(), got_w.data(), n), -1)
                  << "windowDepthFromMetres " << test::pathName(path) << " n " << n << " draws " << draws;
              EXPECT_EQ(got_bad, want_bad) << test::pathName(path) << " n " << n << " draws " << draws;
            }
          }
        }
      }
    }
  }
}

// depthMetresMaskingPrimitives is depthMetres, maskPrimitiveIds and largestDrawId, on every path
// (AVX2's one pass among them), at sizes around the blocks: ids 0, valid, out of range and with the
// top bit set.
TEST(CameraModel, DepthMaskingPrimitivesIsTheThreePasses) {
  std::vector<Instructions> paths = test::vectorPaths();
  paths.push_back(Instructions::kScalar);
  std::mt19937 rng(5);
  for (size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 33, 1000, 1921 * 3 + 5}) {
    for (uint32_t draws : {0u, 6u, 300u}) {
      const CaptureFrame f = randomDepthFrame(rng, n, draws);
      const FrameCamera camera{GlMatrix::Identity(), randomProjection(rng), 1};
      std::vector<uint32_t> primitives(n);
      for (uint32_t& p : primitives) p = static_cast<uint32_t>(rng());
      const std::vector<float> want_metres = depthMetres(f, &camera, Instructions::kScalar);
      std::vector<int32_t> want_primitives(n);
      maskPrimitiveIds(f.draw_ids.data(), primitives.data(), n, want_primitives.data());
      const uint32_t want_largest = n ? *std::max_element(f.draw_ids.begin(), f.draw_ids.end()) : 0;
      for (Instructions path : paths) {
        const std::string what =
            std::string(test::pathName(path)) + " n " + std::to_string(n) + " draws " + std::to_string(draws);
        std::vector<float> metres = f.depth_window;  // in place, as the bridge converts
        std::vector<uint32_t> masked = primitives;
        auto* out = reinterpret_cast<int32_t*>(masked.data());
        const uint32_t largest =
            depthMetresMaskingPrimitives(f, f.draw_ids.data(), metres.data(), &camera, metres.data(), out, path);
        EXPECT_EQ(largest, want_largest) << what;
        EXPECT_EQ(test::firstDifference(want_metres.data(), metres.data(), n), -1) << what;
        EXPECT_EQ(std::memcmp(want_primitives.data(), out, 4 * n), 0) << what;
      }
    }
  }
}

TEST(CameraModel, OpticalFrameAxes) {
  // OpenGL camera: x right, y up, looking down -z. Optical: x right, y down, z forward.
  EXPECT_TRUE((opticalFromGlCamera() * Eigen::Vector3d(0, 0, -2)).isApprox(Eigen::Vector3d(0, 0, 2)));
  EXPECT_TRUE((opticalFromGlCamera() * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE((opticalFromGlCamera() * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_NEAR(opticalFromGlCamera().determinant(), 1.0, 1e-12);  // a rotation, not a reflection

  // World: Z up. Camera at (1, 2, 1.5) looking along +Y.
  const Eigen::Vector3d eye(1, 2, 1.5);
  const Eigen::Isometry3d optical_from_world = opticalFromWorld(glLookAt(eye, eye + Eigen::Vector3d(0, 1, 0)));
  const Eigen::Vector3d ahead = optical_from_world * (eye + Eigen::Vector3d(0, 5, 0));
  const Eigen::Vector3d above = optical_from_world * (eye + Eigen::Vector3d(0, 5, 1));
  const Eigen::Vector3d right = optical_from_world * (eye + Eigen::Vector3d(1, 5, 0));
  EXPECT_TRUE(ahead.isApprox(Eigen::Vector3d(0, 0, 5), 1e-6)) << ahead.transpose();
  EXPECT_TRUE(above.isApprox(Eigen::Vector3d(0, -1, 5), 1e-6)) << above.transpose();
  EXPECT_TRUE(right.isApprox(Eigen::Vector3d(1, 0, 5), 1e-6)) << right.transpose();
  // The inverse is the camera pose: its translation is the camera position in the world.
  EXPECT_TRUE(optical_from_world.inverse().translation().isApprox(eye, 1e-6));
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
