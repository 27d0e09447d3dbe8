// checkReprojection on a frame whose pixels are known: an axis-aligned quad facing the camera,
// rasterised here by pixel centres, then the same frame with a wrong matrix, id or depth.
#include "viper/ground_truth/capture_invariants.h"

#include <gtest/gtest.h>

#include <cmath>

using viper::CaptureFrame;
using viper::GlMatrix;

namespace {

constexpr uint32_t kW = 80, kH = 60;
constexpr float kDistance = 5.0f;

GlMatrix perspective(float fovy_rad, float aspect, float n, float f) {
  GlMatrix p = GlMatrix::Zero();
  const float t = 1.0f / std::tan(fovy_rad / 2);
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = (f + n) / (n - f);
  p(2, 3) = 2 * f * n / (n - f);
  p(3, 2) = -1;
  return p;
}

// A 2 x 2 quad at z = -kDistance (two triangles split along x = y), drawn as draw 0 with its
// world matrix moving it by `shift` in x; pixels by centre, triangle by side of the diagonal.
struct QuadScene {
  CaptureFrame frame;
  viper::MeshRegistry meshes;

  explicit QuadScene(float shift = 0.0f) {
    viper::MeshRecord mesh;
    mesh.key = 42;
    mesh.positions_xyz = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    mesh.indices = {0, 1, 2, 0, 2, 3};  // 0: below the diagonal (y < x), 1: above
    meshes.add(mesh);
    frame.width = kW;
    frame.height = kH;
    viper::DrawRecord d;
    d.mesh_key = 42;
    d.matrix_flags = viper::kHasWorld | viper::kHasView | viper::kHasProjection;
    d.world(0, 3) = shift;
    d.world(2, 3) = -kDistance;
    d.projection = perspective(1.0f, static_cast<float>(kW) / kH, 0.5f, 100.0f);
    frame.draws.push_back(d);
    const size_t n = frame.pixelCount();
    frame.depth_window.assign(n, 1.0f);
    frame.draw_ids.assign(n, 0);
    frame.primitive_ids.assign(n, 0);
    const GlMatrix& P = d.projection;
    const float ndc_z = (P(2, 2) * -kDistance + P(2, 3)) / kDistance;
    for (uint32_t r = 0; r < kH; ++r) {
      for (uint32_t c = 0; c < kW; ++c) {
        // Pixel centre back to the quad's plane: world x, y of the ray at z = -kDistance.
        const float ndc_x = (c + 0.5f) / kW * 2 - 1, ndc_y = (kH - 1 - r + 0.5f) / kH * 2 - 1;
        const float x = ndc_x * kDistance / P(0, 0), y = ndc_y * kDistance / P(1, 1);
        if (std::abs(x) > 1 || std::abs(y) > 1) continue;
        const size_t px = static_cast<size_t>(r) * kW + c;
        frame.depth_window[px] = (ndc_z + 1) / 2;
        frame.draw_ids[px] = 1;
        frame.primitive_ids[px] = y < x ? 0 : 1;
      }
    }
  }
};

}  // namespace

TEST(CaptureInvariants, PixelsOfAProjectedQuadLieOnTheirTriangles) {
  QuadScene s;
  const viper::ReprojectionCheck c = viper::checkReprojection(s.frame, s.meshes);
  EXPECT_GT(c.checked_pixels, 400u);  // about 22 x 22 px
  EXPECT_EQ(c.scene_pixels, c.id_pixels);
  EXPECT_EQ(c.id_pixels, c.placed_pixels);
  EXPECT_EQ(c.placed_pixels, c.checked_pixels);
  // Pixel centres on the diagonal may fall either side: within float rounding of it.
  EXPECT_LT(viper::quantile(c.distance_px, 1.0), 1e-3f);
  EXPECT_LT(viper::quantile(c.depth_relative, 1.0), 1e-5f);
}

TEST(CaptureInvariants, AWrongWorldMatrixShowsAsDistance) {
  QuadScene truth;
  QuadScene moved(0.25f);  // the pixels of the true quad checked against a quad moved 0.25 m
  truth.frame.draws[0].world = moved.frame.draws[0].world;
  const viper::ReprojectionCheck c = viper::checkReprojection(truth.frame, truth.meshes);
  // 0.25 m at 5 m with this projection is about 2.6 px: the left strip and the pixels near the
  // diagonal now miss their triangle.
  EXPECT_GT(viper::quantile(c.distance_px, 0.99), 1.5f);
}

TEST(CaptureInvariants, AWrongPrimitiveOrDepthShows) {
  QuadScene s;
  for (uint32_t& p : s.frame.primitive_ids) p = 1 - p;  // every pixel names the other triangle
  viper::ReprojectionCheck c = viper::checkReprojection(s.frame, s.meshes);
  EXPECT_GT(viper::quantile(c.distance_px, 0.5), 1.0f);

  QuadScene d;
  for (float& z : d.frame.depth_window)
    if (z < 1.0f) z = z + 0.5f * (1.0f - z);  // farther away
  c = viper::checkReprojection(d.frame, d.meshes);
  EXPECT_LT(viper::quantile(c.distance_px, 1.0), 1e-3f);
  EXPECT_GT(viper::quantile(c.depth_relative, 0.5), 0.1f);
}

// A quad drawn on the far plane, as a sky dome is (gl_Position = p.xyww): its pixels lie on their
// triangles, but their window depth is 1 (no surface, NaN as published), not the mesh's: they are
// counted and left out of the depth comparison rather than failing it.
TEST(CaptureInvariants, PixelsAtTheFarPlaneAreCountedNotDepthChecked) {
  QuadScene s;
  size_t quad = 0;
  for (size_t px = 0; px < s.frame.pixelCount(); ++px)
    if (s.frame.draw_ids[px] != 0 && px % 3 == 0) s.frame.depth_window[px] = 1.0f, ++quad;
  const viper::ReprojectionCheck c = viper::checkReprojection(s.frame, s.meshes);
  ASSERT_GT(quad, 100u);
  EXPECT_EQ(c.far_plane_pixels, quad);
  EXPECT_EQ(c.depth_relative.size() + quad, c.checked_pixels);
  EXPECT_EQ(c.distance_px.size(), c.checked_pixels) << "their place is still checked";
  EXPECT_LT(viper::quantile(c.distance_px, 1.0), 1e-3f);
  EXPECT_LT(viper::quantile(c.depth_relative, 1.0), 1e-5f);
}

TEST(CaptureInvariants, UnplacedDrawsAreCountedNotChecked) {
  QuadScene s;
  s.frame.draws[0].matrix_flags = viper::kHasView | viper::kHasProjection;  // no world matrix
  viper::ReprojectionCheck c = viper::checkReprojection(s.frame, s.meshes);
  EXPECT_GT(c.id_pixels, 0u);
  EXPECT_EQ(c.placed_pixels, 0u);
  EXPECT_TRUE(c.distance_px.empty());
  s.meshes = viper::MeshRegistry();
  s.frame.draws[0].matrix_flags |= viper::kHasWorld;
  c = viper::checkReprojection(s.frame, s.meshes);
  EXPECT_EQ(c.placed_pixels, 0u);
}

namespace {

// Two frames of a textured image moving 3 px right, with the flow both ways; `bwd_error` is added
// to the backward flow's u.
struct ShiftPair {
  CaptureFrame a, b;
  viper::FlowField fwd, bwd;

  explicit ShiftPair(float bwd_error = 0.0f) {
    for (CaptureFrame* f : {&a, &b}) {
      f->width = kW, f->height = kH;
      f->color_rgb.assign(kW * kH * 3, 0);
      f->draw_ids.assign(kW * kH, 1);
    }
    auto texture = [](int x, int y) { return static_cast<uint8_t>((x * 37 + y * 11 + (x * y) % 7) % 256); };
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x)
        for (int c = 0; c < 3; ++c) {
          a.color_rgb[(y * kW + x) * 3 + c] = texture(static_cast<int>(x), static_cast<int>(y));
          b.color_rgb[(y * kW + x) * 3 + c] = texture(static_cast<int>(x) - 3, static_cast<int>(y));
        }
    for (viper::FlowField* f : {&fwd, &bwd}) {
      f->width = kW, f->height = kH;
      f->uv.assign(kW * kH * 2, 0.0f);
      f->visible.assign(kW * kH, 255);
    }
    for (size_t i = 0; i < kW * kH; ++i) fwd.uv[2 * i] = 3.0f, bwd.uv[2 * i] = -3.0f + bwd_error;
  }
};

}  // namespace

TEST(CaptureInvariants, ConsistentFlowGoesBackAndWarpsTheImage) {
  ShiftPair p;
  const viper::FlowConsistencyCheck c = viper::checkFlowPair(p.a, p.b, p.fwd, p.bwd);
  EXPECT_EQ(c.flow_pixels, kW * kH);
  EXPECT_EQ(c.visible_pixels, (kW - 3) * kH);  // the last 3 columns land outside b
  EXPECT_LT(viper::quantile(c.forward_backward_px, 1.0), 1e-6f);
  EXPECT_LT(c.photometricFlow(), 1e-9);
  EXPECT_GT(c.photometricZero(), 10.0);
}

TEST(CaptureInvariants, InconsistentFlowShows) {
  ShiftPair p(0.5f);
  viper::FlowConsistencyCheck c = viper::checkFlowPair(p.a, p.b, p.fwd, p.bwd);
  EXPECT_NEAR(viper::quantile(c.forward_backward_px, 0.5), 0.5f, 1e-5f);
  ShiftPair q;
  for (size_t i = 0; i < kW * kH; ++i) q.fwd.uv[2 * i] = 2.0f;  // a wrong forward flow warps wrongly
  c = viper::checkFlowPair(q.a, q.b, q.fwd, q.bwd);
  EXPECT_GT(c.photometricFlow(), 5.0);
  EXPECT_NEAR(viper::quantile(c.forward_backward_px, 0.5), 1.0f, 1e-5f);
}

TEST(CaptureInvariants, StaticSurfacesMoveAsTheCameraDoes) {
  // The quad stays; the camera moves 0.2 to the right between a and b, so every pixel of the quad
  // moves left by P00 * 0.2 / kDistance in NDC. A flow that says so agrees with the ego flow.
  QuadScene sa, sb;
  sb.frame.draws[0].view(0, 3) = -0.2f;
  const float shift_px = -sa.frame.draws[0].projection(0, 0) * 0.2f / kDistance * kW / 2;
  viper::FlowField fwd;
  fwd.width = kW, fwd.height = kH;
  fwd.uv.assign(kW * kH * 2, NAN);
  fwd.visible.assign(kW * kH, 255);
  for (size_t i = 0; i < kW * kH; ++i)
    if (sa.frame.draw_ids[i]) fwd.uv[2 * i] = shift_px, fwd.uv[2 * i + 1] = 0.0f;
  viper::StaticFlowCheck c = viper::checkStaticFlow(sa.frame, sb.frame, {0}, fwd);
  ASSERT_GT(c.static_pixels, 100u);
  EXPECT_EQ(c.error_px.size(), c.static_pixels);
  EXPECT_LT(viper::quantile(c.error_px, 1.0), 1e-3f);
  // A flow half a pixel off shows; so does a draw that moved (not static: not checked).
  for (size_t i = 0; i < kW * kH; ++i)
    if (sa.frame.draw_ids[i]) fwd.uv[2 * i] += 0.5f;
  c = viper::checkStaticFlow(sa.frame, sb.frame, {0}, fwd);
  EXPECT_NEAR(viper::quantile(c.error_px, 0.5), 0.5f, 1e-3f);
  sb.frame.draws[0].world(1, 3) = 0.1f;
  c = viper::checkStaticFlow(sa.frame, sb.frame, {0}, fwd);
  EXPECT_EQ(c.static_pixels, 0u);
  EXPECT_TRUE(viper::checkStaticFlow(sa.frame, sb.frame, {-1}, fwd).error_px.empty()) << "no association";
}

TEST(CaptureInvariants, PixelsOfAnObjectLieInItsBox) {
  QuadScene s;
  viper::FrameObject o;
  o.draws = {0};
  o.world = s.frame.draws[0].world;
  o.pixel_count = 1;
  const viper::BoxCheck c = viper::checkBoxes(s.frame, {o}, s.meshes);
  EXPECT_EQ(c.objects, 1u);
  ASSERT_GT(c.pixels, 100u);
  EXPECT_LT(viper::quantile(c.outside_relative, 1.0), 1e-5f) << "the quad's points on its (flat) box";
  // A box made from half the mesh leaves most of the quad's points outside it.
  viper::MeshRecord half = *s.meshes.find(42);
  for (float& v : half.positions_xyz) v *= 0.5f;
  s.meshes.add(half);
  const viper::BoxCheck d = viper::checkBoxes(s.frame, {o}, s.meshes);
  EXPECT_GT(viper::quantile(d.outside_relative, 0.5), 0.01f);
  o.pixel_count = 0;
  EXPECT_EQ(viper::checkBoxes(s.frame, {o}, s.meshes).objects, 0u) << "objects without pixels are not checked";
}
