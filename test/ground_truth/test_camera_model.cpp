// Camera model: intrinsics and depth from OpenGL matrices, checked against the OpenGL pipeline
// itself (clip -> NDC -> window transform as the GL specification defines it).
#include "viper/ground_truth/camera_model.h"

#include "../common/gl_matrices.h"

#include <gtest/gtest.h>

#include <cmath>
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
