#include "viper/ground_truth/flow.h"

#include "rigid_flow_case.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace viper {
namespace {

using namespace test;

TEST(Flow, RigidFlowMatchesTheAnalyticMotionOfTheSurface) {
  RigidCase c;
  FlowStats stats;
  const FlowField f = computeFlow(c.a, c.b, {0}, c.depthB(), MeshRegistry(), FlowOptions(), &stats);
  ASSERT_GT(stats.rigid, 500u);
  EXPECT_LT(worstRigidError(c, f), 2e-3) << "worst endpoint error (px) against the analytic motion";
}

// Rows are computed in blocks of 8 pixels where the CPU allows, and the rest of a row one pixel at
// a time: at a width of 16 + 5 both kinds meet in most rows of the square. The mask is checked
// against the occlusion rule applied at the analytic target.
TEST(Flow, RigidFlowIsTheSameInBlocksAndAtTheEndOfARow) {
  RigidCase c(21);
  FlowStats stats;
  const std::vector<float> depth_b = c.depthB();
  const FlowField f = computeFlow(c.a, c.b, {0}, depth_b, MeshRegistry(), FlowOptions(), &stats);
  size_t at_end = 0, mask_wrong = 0, seen = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(c.w); ++x) {
      auto hit = c.cast(c.view_a, c.world_a, x, y);
      if (!hit) continue;
      at_end += x >= 16;
      const Eigen::Vector3d local = Eigen::Affine3d(c.world_a.cast<double>()).inverse() * *hit;
      const Eigen::Vector3d moved = Eigen::Affine3d(c.world_b.cast<double>()) * local;
      const Eigen::Vector2d target = projectPixel(c.proj, c.view_b, moved, c.w);
      const double depth = -(c.view_b.cast<double>() * moved.homogeneous()).z();
      bool expected = target.x() >= -0.5 && target.y() >= -0.5 && target.x() < c.w - 0.5 && target.y() < kH - 0.5;
      if (expected) {
        const float there = depth_b[long(target.y() + 0.5) * c.w + long(target.x() + 0.5)];
        expected = !(there < depth * (1 - FlowOptions().occlusion_relative) - FlowOptions().occlusion_absolute_m);
      }
      mask_wrong += (f.visible[y * c.w + x] == 255) != expected;
      seen += expected;
    }
  ASSERT_GT(at_end, 20u) << "the square reaches the last pixels of its rows";
  EXPECT_GT(seen, 100u);
  EXPECT_LE(mask_wrong, 2u) << "pixels whose mask differs from the rule at the true target (rounding at borders)";
  EXPECT_LT(worstRigidError(c, f), 2e-3) << "worst endpoint error (px), all pixels";
  EXPECT_LT(worstRigidError(c, f, 16), 2e-3) << "worst endpoint error (px), the last 5 pixels of each row";
  size_t square = 0;
  for (uint32_t id : c.a.draw_ids) square += id == 1;
  EXPECT_EQ(stats.rigid, square);
  EXPECT_EQ(stats.no_surface, c.a.draw_ids.size() - square);
}

// At a width of 16 + 8 + 5 a row has one block of 16 (AVX-512), one of 8 (AVX2) and 5 pixels done
// one at a time; the paths must agree: the block kernels bit for bit, one pixel at a time to float
// rounding. The wider path is skipped where the CPU lacks it.
TEST(Flow, EveryInstructionPathGivesTheSameFlow) {
  RigidCase c(29);
  const std::vector<float> depth_b = c.depthB();
  auto flowWith = [&](FlowInstructions path, FlowStats* stats) {
    FlowOptions options;
    options.instructions = path;
    return computeFlow(c.a, c.b, {0}, depth_b, MeshRegistry(), options, stats);
  };
  EXPECT_EQ(flowInstructionsUsed(FlowInstructions::kScalar), FlowInstructions::kScalar);
  EXPECT_EQ(flowInstructionsUsed(FlowInstructions::kWidest), flowInstructionsUsed(FlowInstructions::kAvx512));
  FlowStats scalar_stats;
  const FlowField scalar = flowWith(FlowInstructions::kScalar, &scalar_stats);
  ASSERT_GT(scalar_stats.rigid, 300u);
  EXPECT_LT(worstRigidError(c, scalar), 2e-3);
  if (flowInstructionsUsed(FlowInstructions::kAvx2) != FlowInstructions::kAvx2) GTEST_SKIP() << "no AVX2 on this CPU";
  FlowStats avx2_stats;
  const FlowField avx2 = flowWith(FlowInstructions::kAvx2, &avx2_stats);
  EXPECT_EQ(avx2_stats.rigid, scalar_stats.rigid);
  EXPECT_EQ(avx2_stats.no_surface, scalar_stats.no_surface);
  double worst = 0;
  for (size_t i = 0; i < scalar.uv.size(); ++i) {
    ASSERT_EQ(std::isnan(scalar.uv[i]), std::isnan(avx2.uv[i])) << "value " << i;
    if (!std::isnan(scalar.uv[i])) worst = std::max(worst, double(std::abs(scalar.uv[i] - avx2.uv[i])));
  }
  EXPECT_LT(worst, 1e-4) << "px between one pixel at a time and AVX2";
  EXPECT_GT(worst, 0.0) << "the scalar path fuses no multiply-adds: its last bits differ";
  if (flowInstructionsUsed(FlowInstructions::kAvx512) != FlowInstructions::kAvx512)
    GTEST_SKIP() << "no AVX-512 on this CPU";
  FlowStats avx512_stats;
  const FlowField avx512 = flowWith(FlowInstructions::kAvx512, &avx512_stats);
  EXPECT_EQ(differingBits(avx512.uv, avx2.uv), 0u);
  EXPECT_EQ(avx512.visible, avx2.visible);
  EXPECT_EQ(avx512_stats.rigid, avx2_stats.rigid);
  EXPECT_EQ(avx512_stats.no_surface, avx2_stats.no_surface);
}

// Camera b stands in the square, looking as a looks: the half of the square behind b's near plane
// has no flow in any path (its projection runs off to infinity at the camera plane), and is counted
// as such; the half in front keeps its analytic flow.
TEST(Flow, PointsNotInFrontOfTheOtherCamerasNearPlaneHaveNoFlow) {
  RigidCase c(29);
  const Eigen::Vector3d eye(0, 0, 1), ahead = eye + (Eigen::Vector3d(0, 0, 0.5) - Eigen::Vector3d(-6, -1, 2));
  c.view_b = glLookAt(eye, ahead);
  c.world_b = c.world_a;
  c.b.draws[0].view = c.view_b, c.b.draws[0].world = c.world_b;
  const double near = 0.1;  // RigidCase's projection
  const std::vector<float> depth_b(c.w * kH, std::numeric_limits<float>::quiet_NaN());
  size_t behind = 0, in_front = 0;
  std::vector<bool> expect_flow(c.w * kH, false);
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(c.w); ++x)
      if (auto hit = c.cast(c.view_a, c.world_a, x, y)) {
        const double depth = -(c.view_b.cast<double>() * hit->homogeneous()).z();
        if (std::abs(depth - near) < 1e-3) continue;  // too close to call in float
        (depth > near ? in_front : behind)++;
        expect_flow[y * c.w + x] = depth > near;
      }
  ASSERT_GT(behind, 100u);
  ASSERT_GT(in_front, 100u);
  std::vector<FlowInstructions> paths = {FlowInstructions::kScalar};
  if (flowInstructionsUsed(FlowInstructions::kAvx2) == FlowInstructions::kAvx2) paths.push_back(FlowInstructions::kAvx2);
  if (flowInstructionsUsed(FlowInstructions::kAvx512) == FlowInstructions::kAvx512)
    paths.push_back(FlowInstructions::kAvx512);
  for (FlowInstructions path : paths) {
    SCOPED_TRACE(static_cast<int>(path));
    FlowOptions options;
    options.instructions = path;
    FlowStats stats;
    const FlowField f = computeFlow(c.a, c.b, {0}, depth_b, MeshRegistry(), options, &stats);
    size_t wrong = 0, worst_far = 0;
    double worst = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(c.w); ++x) {
        const size_t p = y * c.w + x;
        auto hit = c.cast(c.view_a, c.world_a, x, y);
        if (!hit) continue;
        const double depth = -(c.view_b.cast<double>() * hit->homogeneous()).z();
        if (std::abs(depth - near) < 1e-3) continue;
        wrong += std::isnan(f.uv[2 * p]) == expect_flow[p];
        if (expect_flow[p]) {
          EXPECT_FALSE(std::isnan(f.uv[2 * p + 1]));
        } else {
          EXPECT_TRUE(std::isnan(f.uv[2 * p + 1]));
          EXPECT_EQ(f.visible[p], 0);
        }
        if (!expect_flow[p] || depth < 1.0) continue;  // near the plane a float's rounding is many pixels
        const Eigen::Vector2d target = projectPixel(c.proj, c.view_b, *hit, c.w);
        const double error = (Eigen::Vector2d(f.uv[2 * p], f.uv[2 * p + 1]) - (target - Eigen::Vector2d(x, y))).norm();
        worst = std::max(worst, error);
        ++worst_far;
      }
    EXPECT_EQ(wrong, 0u) << "pixels whose flow is defined where the point is behind b's near plane, or the reverse";
    EXPECT_GT(worst_far, 20u);
    EXPECT_LT(worst, 1e-2) << "worst endpoint error (px) at 1 m or more in front of b";
    EXPECT_GE(stats.behind_b, behind);
    EXPECT_LE(stats.behind_b, behind + (c.a.draw_ids.size() - behind - in_front));
    EXPECT_EQ(stats.rigid + stats.behind_b + stats.no_surface, c.a.draw_ids.size());
  }
}

TEST(Flow, ForwardThenBackwardReturnsToThePixel) {
  RigidCase c;
  std::vector<float> depth_a(kW * kH, std::numeric_limits<float>::quiet_NaN());
  const FlowField fwd = computeFlow(c.a, c.b, {0}, c.depthB(), MeshRegistry());
  const FlowField bwd = computeFlow(c.b, c.a, {0}, depth_a, MeshRegistry());
  int checked = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      const size_t p = y * kW + x;
      if (std::isnan(fwd.uv[2 * p])) continue;
      const double xb = x + fwd.uv[2 * p], yb = y + fwd.uv[2 * p + 1];
      const long xi = std::lround(xb), yi = std::lround(yb);
      if (xi < 0 || yi < 0 || xi >= long(kW) || yi >= long(kH)) continue;
      const size_t q = yi * kW + xi;
      if (std::isnan(bwd.uv[2 * q])) continue;
      // The backward flow of b's pixel q lands near x, y; sub-pixel offsets differ by the
      // rounding (xb - xi), which a locally affine flow carries over almost exactly.
      const double back_x = xi + bwd.uv[2 * q] - (xi - xb), back_y = yi + bwd.uv[2 * q + 1] - (yi - yb);
      EXPECT_NEAR(back_x, x, 0.05);
      EXPECT_NEAR(back_y, y, 0.05);
      ++checked;
    }
  EXPECT_GT(checked, 400);
}

TEST(Flow, NonRigidTriangleFollowsItsBarycentrics) {
  const GlMatrix proj = glPerspective(0.9, double(kW) / kH, 0.1, 300);
  const GlMatrix view = glLookAt({-5, 0, 1}, {0, 0, 1});
  const std::array<Eigen::Vector3d, 3> xa = {{{0, -1.5, 0}, {0.5, 1.5, 0.2}, {-0.3, 0, 2.4}}};
  const std::array<Eigen::Vector3d, 3> xb = {{{0.1, -1.4, 0}, {0.2, 1.7, 0.4}, {0.4, 0.3, 2.2}}};  // deformed
  MeshRecord mesh;
  mesh.key = 5;
  mesh.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};  // rest pose, unused by the non-rigid path
  mesh.indices = {0, 1, 2};
  MeshRegistry store;
  store.add(mesh);
  CaptureFrame a = emptyFrame(), b = emptyFrame();
  DrawRecord d;
  d.mesh_key = 5, d.view = view, d.projection = proj, d.matrix_flags = kHasWorld | kHasView | kHasProjection;
  DrawRecord da = d, db = d;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector4f ca = (proj * view).cast<float>() * xa[i].cast<float>().homogeneous();
    const Eigen::Vector4f cb = (proj * view).cast<float>() * xb[i].cast<float>().homogeneous();
    da.deformed_clip_xyzw.insert(da.deformed_clip_xyzw.end(), {ca.x(), ca.y(), ca.z(), ca.w()});
    db.deformed_clip_xyzw.insert(db.deformed_clip_xyzw.end(), {cb.x(), cb.y(), cb.z(), cb.w()});
  }
  a.draws = {da};
  b.draws = {db};
  // Ray-cast triangle a for the oracle: hit point and its true barycentrics.
  std::vector<std::optional<Eigen::Vector3d>> bary(kW * kH);
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      auto [o, dir] = pixelRay(proj, view, x, y);
      const Eigen::Vector3d e1 = xa[1] - xa[0], e2 = xa[2] - xa[0];
      Eigen::Matrix3d m;
      m << -dir, e1, e2;
      const Eigen::Vector3d sol = m.fullPivLu().solve(o - xa[0]);  // t, b1, b2
      if (sol.x() <= 0 || sol.y() < 0 || sol.z() < 0 || sol.y() + sol.z() > 1) continue;
      const size_t p = y * kW + x;
      a.draw_ids[p] = 1;
      a.depth_window[p] = windowDepth(proj, view, o + sol.x() * dir);
      bary[p] = Eigen::Vector3d(1 - sol.y() - sol.z(), sol.y(), sol.z());
    }
  std::vector<float> depth_b(kW * kH, std::numeric_limits<float>::quiet_NaN());
  FlowStats stats;
  const FlowField f = computeFlow(a, b, {0}, depth_b, store, FlowOptions(), &stats);
  ASSERT_GT(stats.non_rigid, 300u);
  double worst = 0;
  for (size_t p = 0; p < bary.size(); ++p) {
    if (!bary[p]) continue;
    const Eigen::Vector3d moved = (*bary[p])[0] * xb[0] + (*bary[p])[1] * xb[1] + (*bary[p])[2] * xb[2];
    const Eigen::Vector2d expected = projectPixel(proj, view, moved) - Eigen::Vector2d(p % kW, p / kW);
    worst = std::max(worst, (Eigen::Vector2d(f.uv[2 * p], f.uv[2 * p + 1]) - expected).norm());
    EXPECT_EQ(f.visible[p], 255);
  }
  EXPECT_LT(worst, 1e-3);
}

TEST(Flow, OcclusionMaskComparesWithTheOtherFramesDepth) {
  RigidCase c;
  std::vector<float> wall(kW * kH, 0.5f);  // something 0.5 m in front of the camera everywhere
  FlowStats stats;
  const FlowField hidden = computeFlow(c.a, c.b, {0}, wall, MeshRegistry(), FlowOptions(), &stats);
  const FlowField seen = computeFlow(c.a, c.b, {0}, c.depthB(), MeshRegistry());
  size_t with_flow = 0, visible = 0, hidden_visible = 0;
  for (size_t p = 0; p < kW * kH; ++p) {
    if (std::isnan(seen.uv[2 * p])) continue;
    ++with_flow;
    visible += seen.visible[p] == 255;
    hidden_visible += hidden.visible[p] == 255;
    EXPECT_EQ(hidden.uv[2 * p], seen.uv[2 * p]) << "occluded points keep their flow";
  }
  EXPECT_EQ(hidden_visible, 0u);
  EXPECT_GT(visible, with_flow * 9 / 10);
}

// Regression: the rigid path compared b's depth with depth_b / depth_a (~1 m) instead of metres, so
// almost every point counted as visible (found by test_flow_against_oracle). A surface 10 % nearer
// than the point hides it; one 10 % farther does not.
TEST(Flow, RigidOcclusionUsesThePointsDepthInMetres) {
  RigidCase c;
  std::vector<float> nearer = c.depthB(), farther = c.depthB();
  for (float& d : nearer) d *= 0.9f;
  for (float& d : farther) d *= 1.1f;
  // Where b shows the surface, the moved point lies on it; elsewhere b has no depth at all.
  for (size_t p = 0; p < kW * kH; ++p)
    if (std::isnan(nearer[p])) nearer[p] = farther[p] = 1000.0f;
  const FlowField hidden = computeFlow(c.a, c.b, {0}, nearer, MeshRegistry());
  const FlowField seen = computeFlow(c.a, c.b, {0}, farther, MeshRegistry());
  size_t with_flow = 0, hidden_visible = 0, seen_visible = 0, inside = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      const size_t p = y * kW + x;
      if (std::isnan(seen.uv[2 * p])) continue;
      ++with_flow;
      const int xb = static_cast<int>(std::lround(x + seen.uv[2 * p])), yb = static_cast<int>(std::lround(y + seen.uv[2 * p + 1]));
      if (xb < 0 || yb < 0 || xb >= int(kW) || yb >= int(kH) || !c.b.draw_ids[yb * kW + xb]) continue;
      ++inside;
      hidden_visible += hidden.visible[p] == 255;
      seen_visible += seen.visible[p] == 255;
    }
  ASSERT_GT(inside, with_flow / 2);
  EXPECT_EQ(hidden_visible, 0u) << "of " << inside << " points that land on b's surface";
  EXPECT_EQ(seen_visible, inside);
}

TEST(Flow, MissingAssociationAndBadSizes) {
  RigidCase c;
  FlowStats stats;
  const FlowField f = computeFlow(c.a, c.b, {-1}, c.depthB(), MeshRegistry(), FlowOptions(), &stats);
  EXPECT_EQ(stats.rigid, 0u);
  EXPECT_GT(stats.no_association, 500u);
  for (float v : f.uv) EXPECT_TRUE(std::isnan(v));
  EXPECT_THROW(computeFlow(c.a, c.b, {0, 1}, c.depthB(), MeshRegistry()), std::invalid_argument);
  CaptureFrame small = emptyFrame();
  small.width = 10;
  EXPECT_THROW(computeFlow(c.a, small, {0}, c.depthB(), MeshRegistry()), std::invalid_argument);
}

TEST(Flow, AssociationByTrackByPlacementAndByUniqueMesh) {
  CaptureFrame a, b;
  auto draw = [](uint64_t mesh, float x) {
    DrawRecord d;
    d.mesh_key = mesh;
    d.world(0, 3) = x;
    return d;
  };
  a.draws = {draw(1, 0), draw(1, 5), draw(2, 0), draw(3, 0), draw(9, 0)};
  b.draws = {draw(3, 1), draw(1, 5), draw(9, 9), draw(1, 0), draw(2, 7)};
  // Draw 4 (mesh 9) belongs to track 12 in both frames, but b's is at index 2.
  const auto m = associateDraws(a, {0, 0, 0, 0, 12}, b, {0, 0, 12, 0, 0});
  EXPECT_EQ(m, (std::vector<int32_t>{3, 1, 4, 0, 2}));
}

}  // namespace
}  // namespace viper
