// A rigid flow case for tests: a unit square placed in two frames, "rendered" by ray casting, with
// its analytic motion; and the helpers that compare flows with it.
#pragma once

#include "viper/ground_truth/flow.h"

#include "../common/gl_matrices.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace viper {
namespace test {

inline constexpr uint32_t kW = 96, kH = 64;

// Ray through the center of pixel (x, y) in world coordinates: origin and direction.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> pixelRay(const GlMatrix& proj, const GlMatrix& view, int x, int y,
                                                     uint32_t width = kW) {
  const Eigen::Matrix4d inv = (proj.cast<double>() * view.cast<double>()).inverse();
  const double nx = 2.0 * (x + 0.5) / width - 1, ny = 1.0 - 2.0 * (y + 0.5) / kH;
  Eigen::Vector4d a = inv * Eigen::Vector4d(nx, ny, -1, 1), b = inv * Eigen::Vector4d(nx, ny, 1, 1);
  const Eigen::Vector3d p0 = a.head<3>() / a.w(), p1 = b.head<3>() / b.w();
  return {p0, (p1 - p0).normalized()};
}

inline Eigen::Vector2d projectPixel(const GlMatrix& proj, const GlMatrix& view, const Eigen::Vector3d& p,
                             uint32_t width = kW) {
  const Eigen::Vector4d c = proj.cast<double>() * view.cast<double>() * p.homogeneous();
  return {(c.x() / c.w() + 1) * 0.5 * width - 0.5, (1 - c.y() / c.w()) * 0.5 * kH - 0.5};
}

inline float windowDepth(const GlMatrix& proj, const GlMatrix& view, const Eigen::Vector3d& p) {
  const Eigen::Vector4d c = proj.cast<double>() * view.cast<double>() * p.homogeneous();
  return static_cast<float>((c.z() / c.w() + 1) * 0.5);
}

inline CaptureFrame emptyFrame(uint32_t width = kW) {
  CaptureFrame f;
  f.width = width, f.height = kH;
  f.depth_window.assign(width * kH, 1.0f);
  f.draw_ids.assign(width * kH, 0);
  f.primitive_ids.assign(width * kH, 0);
  f.color_rgb.assign(width * kH * 3, 0);
  return f;
}

// A unit square (object z = 0, |x|, |y| <= 1) placed with `world`, "rendered" by ray casting into
// frames `w` pixels wide.
struct RigidCase {
  uint32_t w;
  GlMatrix proj = glPerspective(0.9, double(w) / kH, 0.1, 300);
  GlMatrix view_a = glLookAt({-6, -1, 2}, {0, 0, 0.5}), view_b = glLookAt({-5.6, -0.8, 2.05}, {0, 0.1, 0.5});
  GlMatrix world_a, world_b;
  CaptureFrame a = emptyFrame(w), b = emptyFrame(w);
  explicit RigidCase(uint32_t width = kW) : w(width) { renderBoth(); }
  // Each frame's depth in metres along the optical axis, exact (from the hit, not the window
  // depth), NaN where the square is not.
  std::vector<float> metres_a, metres_b;
  // The same case under another projection (an orthographic one, say).
  RigidCase(uint32_t width, const GlMatrix& projection) : w(width), proj(projection) { renderBoth(); }
  void renderBoth() {
    Eigen::Affine3d wa = Eigen::Translation3d(0, 0, 1) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()) * Eigen::Scaling(2.0);
    Eigen::Affine3d wb = Eigen::Translation3d(0.15, 0.05, 1) * Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()) * Eigen::Scaling(2.0);
    world_a = wa.matrix().cast<float>(), world_b = wb.matrix().cast<float>();
    metres_a = render(a, view_a, world_a);
    metres_b = render(b, view_b, world_b);
  }
  std::vector<float> render(CaptureFrame& f, const GlMatrix& view, const GlMatrix& world) {
    std::vector<float> metres(w * kH, std::numeric_limits<float>::quiet_NaN());
    DrawRecord d;
    d.mesh_key = 77, d.world = world, d.view = view, d.projection = proj;
    d.matrix_flags = kHasWorld | kHasView | kHasProjection;
    f.draws = {d};
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(w); ++x)
        if (auto hit = cast(view, world, x, y)) {
          f.draw_ids[y * w + x] = 1;
          f.depth_window[y * w + x] = windowDepth(proj, view, *hit);
          metres[y * w + x] = static_cast<float>(-(view.cast<double>() * hit->homogeneous()).z());
        }
    return metres;
  }
  std::optional<Eigen::Vector3d> cast(const GlMatrix& view, const GlMatrix& world, int x, int y) const {
    auto [o, dir] = pixelRay(proj, view, x, y, w);
    const Eigen::Affine3d placed(world.cast<double>());
    const Eigen::Vector3d n = placed.linear().col(2), c = placed.translation();
    const double t = n.dot(c - o) / n.dot(dir);
    const Eigen::Vector3d p = o + t * dir, local = placed.inverse() * p;
    if (t <= 0 || std::abs(local.x()) > 1 || std::abs(local.y()) > 1) return std::nullopt;
    return p;
  }
  std::vector<float> depthB() const {
    std::vector<float> m(w * kH, std::numeric_limits<float>::quiet_NaN());
    for (size_t i = 0; i < m.size(); ++i)
      if (b.draw_ids[i]) {
        const double z = 2.0 * b.depth_window[i] - 1;  // invert the standard perspective depth
        m[i] = static_cast<float>(proj(2, 3) / (-z - proj(2, 2)) * -1.0);
      }
    return m;
  }
};

// The worst endpoint error (px) of the rigid case's flow against the analytic motion of the square,
// over the pixels of columns x0 and up; NaN flow must be where the square is not.
inline double worstRigidError(const RigidCase& c, const FlowField& f, int x0 = 0) {
  double worst = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = x0; x < int(c.w); ++x) {
      const size_t p = y * c.w + x;
      auto hit = c.cast(c.view_a, c.world_a, x, y);
      if (!hit) {
        EXPECT_TRUE(std::isnan(f.uv[2 * p])) << x << "," << y;
        continue;
      }
      const Eigen::Vector3d local = Eigen::Affine3d(c.world_a.cast<double>()).inverse() * *hit;
      const Eigen::Vector3d moved = Eigen::Affine3d(c.world_b.cast<double>()) * local;
      const Eigen::Vector2d expected = projectPixel(c.proj, c.view_b, moved, c.w) - Eigen::Vector2d(x, y);
      worst = std::max(worst, (Eigen::Vector2d(f.uv[2 * p], f.uv[2 * p + 1]) - expected).norm());
    }
  return worst;
}

// How many values of x and y differ in their bits (NaN equals NaN of the same bits).
inline size_t differingBits(const std::vector<float>& x, const std::vector<float>& y) {
  EXPECT_EQ(x.size(), y.size());
  size_t n = 0;
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i) n += std::memcmp(&x[i], &y[i], sizeof(float)) != 0;
  return n;
}

}  // namespace test
}  // namespace viper
