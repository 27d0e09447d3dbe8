// Flow from frame a's depth in metres (REP 118, as the depth topic carries it), read where it is:
// the flow node no longer turns it back into window depth. Checked against the analytic motion of
// the square, against the flow from window depth, across the instruction paths, under a
// projection whose window depth is not affine in 1 / metres (orthographic: converted pixel by
// pixel), and for the count of pixels without depth.
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/flow.h"

#include "../common/vector_paths.h"
#include "rigid_flow_case.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace viper {
namespace {

using namespace test;

const float kNaN = std::numeric_limits<float>::quiet_NaN();

// The flow a -> b of `c` from a's metres `metres_a` (default: the exact ones).
FlowField flowFromMetres(const RigidCase& c, FlowInstructions path, FlowStats* stats,
                         const std::vector<float>* metres_a = nullptr, const std::vector<float>* depth_b = nullptr,
                         const GlMatrix* depth_projection = nullptr) {
  FlowFramePixels pa = flowFramePixels(c.a), pb = flowFramePixels(c.b);
  pa.depth_window = nullptr;
  pa.depth_metres = (metres_a ? *metres_a : c.metres_a).data();
  pa.depth_projection = depth_projection;
  FlowOptions options;
  options.instructions = path;
  FlowField f;
  f.width = c.w, f.height = kH;
  f.uv.assign(2 * c.w * kH, 0.0f);
  f.visible.assign(c.w * kH, 7);
  computeFlow(pa, pb, {0}, (depth_b ? *depth_b : c.metres_b).data(), MeshRegistry(), f.uv.data(), f.visible.data(),
              options, stats);
  return f;
}

// The same from window depth (as captured).
FlowField flowFromWindow(const RigidCase& c, FlowInstructions path, FlowStats* stats,
                         const std::vector<float>* depth_b = nullptr) {
  FlowOptions options;
  options.instructions = path;
  return computeFlow(c.a, c.b, {0}, depth_b ? *depth_b : c.metres_b, MeshRegistry(), options, stats);
}

size_t squarePixels(const RigidCase& c) {
  size_t n = 0;
  for (uint32_t id : c.a.draw_ids) n += id == 1;
  return n;
}

// At a width of 16 + 8 + 5, every path meets in most rows: AVX-512 blocks, AVX2 blocks, single pixels.
TEST(FlowFromMetres, MatchesTheAnalyticMotionOnEveryPath) {
  RigidCase c(29);
  const size_t square = squarePixels(c);
  ASSERT_GT(square, 300u);
  for (FlowInstructions path : {FlowInstructions::kScalar, FlowInstructions::kAvx2, FlowInstructions::kAvx512}) {
    if (flowInstructionsUsed(path) != path) continue;
    FlowStats stats;
    const FlowField f = flowFromMetres(c, path, &stats);
    EXPECT_EQ(stats.rigid, square) << test::pathName(path);
    EXPECT_EQ(stats.no_surface, c.a.draw_ids.size() - square) << test::pathName(path);
    EXPECT_EQ(stats.no_depth, 0u) << test::pathName(path);
    EXPECT_LT(worstRigidError(c, f), 2e-3) << "worst endpoint error (px), " << test::pathName(path);
  }
  RigidCase wide;  // 96 pixels a row: blocks nearly everywhere
  EXPECT_LT(worstRigidError(wide, flowFromMetres(wide, FlowInstructions::kWidest, nullptr)), 2e-3);
}

TEST(FlowFromMetres, BlockPathsAgreeBitForBit) {
  RigidCase c(29);
  if (flowInstructionsUsed(FlowInstructions::kAvx512) != FlowInstructions::kAvx512)
    GTEST_SKIP() << "no AVX-512 on this CPU";
  const FlowField avx2 = flowFromMetres(c, FlowInstructions::kAvx2, nullptr);
  const FlowField avx512 = flowFromMetres(c, FlowInstructions::kAvx512, nullptr);
  EXPECT_EQ(differingBits(avx512.uv, avx2.uv), 0u);
  EXPECT_EQ(avx512.visible, avx2.visible);
  const FlowField scalar = flowFromMetres(c, FlowInstructions::kScalar, nullptr);
  double worst = 0;
  for (size_t i = 0; i < scalar.uv.size(); ++i) {
    ASSERT_EQ(std::isnan(scalar.uv[i]), std::isnan(avx2.uv[i])) << "value " << i;
    if (!std::isnan(scalar.uv[i])) worst = std::max(worst, double(std::abs(scalar.uv[i] - avx2.uv[i])));
  }
  EXPECT_LT(worst, 1e-4) << "px between one pixel at a time and AVX2";
}

// The metres the bridge publishes (depthMetres of the window depth) give the flow of the window
// depth they came from, to float rounding, and the same mask.
TEST(FlowFromMetres, GivesTheFlowOfTheWindowDepthItCameFrom) {
  RigidCase c;
  std::vector<float> metres_a(c.a.pixelCount());
  depthMetres(c.a, c.a.draw_ids.data(), c.a.depth_window.data(), nullptr, metres_a.data());
  FlowStats from_window_stats, from_metres_stats;
  const FlowField from_window = flowFromWindow(c, FlowInstructions::kWidest, &from_window_stats);
  const FlowField from_metres =
      flowFromMetres(c, FlowInstructions::kWidest, &from_metres_stats, &metres_a);
  EXPECT_EQ(from_metres_stats.rigid, from_window_stats.rigid);
  double worst = 0;
  size_t mask_differs = 0;
  for (size_t p = 0; p < c.a.pixelCount(); ++p) {
    ASSERT_EQ(std::isnan(from_window.uv[2 * p]), std::isnan(from_metres.uv[2 * p])) << "pixel " << p;
    if (std::isnan(from_window.uv[2 * p])) continue;
    worst = std::max({worst, double(std::abs(from_window.uv[2 * p] - from_metres.uv[2 * p])),
                      double(std::abs(from_window.uv[2 * p + 1] - from_metres.uv[2 * p + 1]))});
    mask_differs += from_window.visible[p] != from_metres.visible[p];
  }
  EXPECT_LT(worst, 1e-3) << "px between the flows from window depth and from its metres";
  EXPECT_LE(mask_differs, 2u);
}

// Where the projection's P33 is not 0 (here a perspective one moved along its axis), window depth
// is not affine in 1 / metres: each pixel is converted to window depth (queued by the block
// kernels), giving the flow of its window depth.
TEST(FlowFromMetres, AProjectionWithP33IsConvertedPixelByPixel) {
  Eigen::Affine3d shift(Eigen::Translation3d(0, 0, -0.5));
  const GlMatrix moved = (glPerspective(0.9, 29.0 / kH, 0.1, 300).cast<double>() * shift.matrix()).cast<float>();
  ASSERT_NE(moved(3, 3), 0.0f);
  RigidCase c(29, moved);
  const size_t square = squarePixels(c);
  ASSERT_GT(square, 100u);
  FlowStats window_stats;
  const FlowField from_window = flowFromWindow(c, FlowInstructions::kScalar, &window_stats);
  EXPECT_LT(worstRigidError(c, from_window), 2e-3) << "the case itself, from window depth";
  for (FlowInstructions path : {FlowInstructions::kScalar, FlowInstructions::kAvx2, FlowInstructions::kAvx512}) {
    if (flowInstructionsUsed(path) != path) continue;
    FlowStats stats;
    const FlowField f = flowFromMetres(c, path, &stats);
    EXPECT_EQ(stats.rigid, square) << test::pathName(path);
    EXPECT_LT(worstRigidError(c, f), 2e-3) << test::pathName(path);
  }
}

// Pixels of a draw without depth are counted, in metres (NaN, 0, negative, infinite) as in window
// depth (1); a draw without any depth is a background and is not. A draw without a projection of
// its own takes depth_projection; without either, none of its pixels has depth.
TEST(FlowFromMetres, CountsThePixelsOfADrawWithoutDepth) {
  RigidCase c(29);
  std::vector<size_t> holes;
  for (size_t p = 0; p < c.a.pixelCount() && holes.size() < 4; p += 7)
    if (c.a.draw_ids[p] == 1) holes.push_back(p);
  ASSERT_EQ(holes.size(), 4u);
  std::vector<float> metres_a = c.metres_a;
  metres_a[holes[0]] = kNaN, metres_a[holes[1]] = 0.0f, metres_a[holes[2]] = -3.0f;
  metres_a[holes[3]] = std::numeric_limits<float>::infinity();
  for (FlowInstructions path : {FlowInstructions::kScalar, FlowInstructions::kWidest}) {
    FlowStats stats;
    const FlowField f = flowFromMetres(c, path, &stats, &metres_a);
    EXPECT_EQ(stats.no_depth, 4u) << test::pathName(path);
    for (size_t p : holes) EXPECT_TRUE(std::isnan(f.uv[2 * p]) && f.visible[p] == 0) << "pixel " << p;
  }
  RigidCase w(29);
  for (size_t p : holes) w.a.depth_window[p] = 1.0f;
  FlowStats window_stats;
  flowFromWindow(w, FlowInstructions::kWidest, &window_stats);
  EXPECT_EQ(window_stats.no_depth, 4u) << "window depth 1 on a drawn pixel";

  std::vector<float> sky(c.a.pixelCount(), kNaN);
  FlowStats sky_stats;
  flowFromMetres(c, FlowInstructions::kWidest, &sky_stats, &sky);
  EXPECT_EQ(sky_stats.no_depth, 0u) << "a draw with no depth at all is a background";
  EXPECT_EQ(sky_stats.rigid, 0u);

  RigidCase own(29);
  own.a.draws[0].matrix_flags &= ~kHasProjection;
  FlowStats none_stats, fallback_stats;
  flowFromMetres(own, FlowInstructions::kWidest, &none_stats);
  EXPECT_EQ(none_stats.rigid, 0u) << "no projection to read the metres with";
  const FlowField f = flowFromMetres(own, FlowInstructions::kWidest, &fallback_stats, nullptr, nullptr, &own.proj);
  EXPECT_EQ(fallback_stats.rigid, squarePixels(own));
  EXPECT_LT(worstRigidError(own, f), 2e-3);
}

TEST(FlowFromMetres, RejectsTwoDepthsOrNone) {
  RigidCase c(29);
  FlowFramePixels pa = flowFramePixels(c.a), pb = flowFramePixels(c.b);
  std::vector<float> uv(2 * c.a.pixelCount());
  std::vector<uint8_t> visible(c.a.pixelCount());
  pa.depth_metres = c.metres_a.data();
  EXPECT_THROW(computeFlow(pa, pb, {0}, c.metres_b.data(), MeshRegistry(), uv.data(), visible.data()),
               std::invalid_argument);
  pa.depth_metres = pa.depth_window = nullptr;
  EXPECT_THROW(computeFlow(pa, pb, {0}, c.metres_b.data(), MeshRegistry(), uv.data(), visible.data()),
               std::invalid_argument);
}

}  // namespace
}  // namespace viper
