// The fixed-function matrix stack, client-side vertex arrays and the end of the scene at a
// depth-only clear: the legacy GL test program (gl_legacy_program.cpp, drawn as Minetest's
// Irrlicht driver draws) plainly and under `capture`, checked against what it knows it drew
// (engine_scene.h); and ModelViewTracker on its own.
#include "engine_scene.h"
#include "matrix_stack.h"
#include "capture_checks.h"
#include "../common/process_util.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace es = viper::engine_scene;
using viper::CaptureFrame;
using viper::GlMatrix;
using viper::capture::ModelViewTracker;

namespace {

constexpr int kWidth = 160, kHeight = 120, kFrames = 3;

struct LegacyRun {
  int plain_rc = -1, capture_rc = -1;
  std::string plain_pixels, captured_pixels;
  std::vector<CaptureFrame> frames;
  viper::MeshRegistry meshes;
};

const LegacyRun& runLegacy() {
  static LegacyRun r;
  static bool done = false;
  if (done) return r;
  done = true;
  const std::string d = viper::test::tempDir("viper_legacy_test_");
  const std::string program = std::string(VIPER_GL_LEGACY_PROGRAM) + " --frames " + std::to_string(kFrames) +
                              " --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight) + " --out ";
  r.plain_rc = viper::test::run(program + d + "/plain.rgba");
  r.capture_rc = viper::test::run(std::string(VIPER_CAPTURE_EXE) + " --output " + d + "/legacy.vcap --profile " +
                                  VIPER_LEGACY_PROFILE + " -- " + program + d + "/captured.rgba");
  r.plain_pixels = viper::test::readFile(d + "/plain.rgba");
  r.captured_pixels = viper::test::readFile(d + "/captured.rgba");
  if (r.capture_rc == 0) {
    viper::test::readCapture(d + "/legacy.vcap", r.frames, r.meshes);
  }
  return r;
}

// Pixel (column, row from the top) of a point in eye space, and of a point of a quad.
std::pair<int, int> pixelOfEye(const Eigen::Vector4f& eye) {
  const Eigen::Vector4f c = es::projection() * eye;
  return {static_cast<int>((c.x() / c.w() + 1) / 2 * kWidth), static_cast<int>((1 - c.y() / c.w()) / 2 * kHeight)};
}
std::pair<int, int> pixelOf(int instance, uint64_t frame, float x, float y) {
  return pixelOfEye(es::view(frame) * es::world(instance, frame) * Eigen::Vector4f(x, y, 0, 1));
}

}  // namespace

TEST(ModelViewTracker, LoadIsTheViewAndWhatFollowsTheWorld) {
  ModelViewTracker t;
  GlMatrix view = GlMatrix::Identity();
  view(2, 3) = -6.0f;
  t.load(view);
  t.multiply(ModelViewTracker::translation(1, 2, 3));
  t.push();
  t.multiply(ModelViewTracker::rotation(90, 0, 0, 1));
  t.multiply(ModelViewTracker::scaling(2, 2, 2));
  Eigen::Affine3f expected = Eigen::Affine3f::Identity();
  expected.translate(Eigen::Vector3f(1, 2, 3)).rotate(Eigen::AngleAxisf(M_PI / 2, Eigen::Vector3f::UnitZ())).scale(2.0f);
  EXPECT_TRUE(t.world().isApprox(expected.matrix(), 1e-6f)) << t.world();
  EXPECT_EQ(t.view(), view);
  t.pop();
  EXPECT_TRUE(t.world().isApprox(ModelViewTracker::translation(1, 2, 3))) << "pop restores the world";
  t.pop();  // underflow: ignored, as GL ignores it
  EXPECT_EQ(t.view(), view);
  t.matrixMode(0x1701);  // GL_PROJECTION: not tracked
  t.load(GlMatrix::Zero());
  t.multiply(GlMatrix::Zero());
  t.matrixMode(0x1700);
  EXPECT_EQ(t.view(), view);
  t.load(GlMatrix::Identity());
  EXPECT_EQ(t.world(), GlMatrix::Identity()) << "a new load starts a new world";
}

TEST(CaptureLegacy, MatrixStackAndClientArraysGiveEveryDrawItsMatricesAndMesh) {
  const LegacyRun& r = runLegacy();
  ASSERT_EQ(r.plain_rc, 0);
  ASSERT_EQ(r.capture_rc, 0);
  ASSERT_EQ(r.plain_pixels.size(), size_t(kWidth) * kHeight * 4);
  EXPECT_TRUE(r.plain_pixels == r.captured_pixels) << "the program's own output changed under capture";
  ASSERT_EQ(r.frames.size(), size_t(kFrames));
  viper::ReprojectionCheck all;
  uint64_t lines_pixels = 0;
  for (const CaptureFrame& f : r.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    EXPECT_EQ(viper::validateFrame(f), "");
    // Draw 0 is the sky, 1 to kInstances the quads, then the line loop, the particle and the
    // refused quad.
    constexpr int kSky = 0, kQuad0 = 1, kLines = es::kInstances + 1, kParticle = kLines + 1, kRefused = kParticle + 1;
    ASSERT_EQ(f.draws.size(), size_t(kRefused) + 1)
        << "the sky, the quads, the line loop, the particle and the refused quad; not the hand (after the depth "
           "clear) or the HUD";
    for (int k = 0; k < es::kInstances; ++k) {
      const viper::DrawRecord& d = f.draws[kQuad0 + k];
      ASSERT_EQ(d.matrix_flags, viper::kHasWorld | viper::kHasView | viper::kHasProjection) << "quad " << k;
      EXPECT_TRUE(d.world.isApprox(es::world(k, f.number), 1e-5f)) << "quad " << k << "\n" << d.world;
      EXPECT_EQ(d.view, es::view(f.number));
      EXPECT_EQ(d.projection, es::projection());
      EXPECT_NE(d.mesh_key, 0u) << "quad " << k << ": a mesh from the conventional vertex array";
      EXPECT_GT(d.visible_pixels, 100u);
      const auto [x, y] = pixelOf(k, f.number, 0.0f, 0.0f);
      ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight);
      EXPECT_EQ(f.draw_ids[size_t(y) * kWidth + x], uint32_t(kQuad0 + k + 1)) << "quad " << k;
    }
    EXPECT_EQ(f.draws[kQuad0].mesh_key, f.draws[kQuad0 + 1].mesh_key) << "the same quad from client memory and from a buffer";
    all.add(viper::checkReprojection(f, r.meshes));
    lines_pixels += f.draws[kLines].visible_pixels;

    // What the layer could not record, reported: the line loop without a mesh (with matrices and
    // ids), the refused quad without ids and without its world. Nothing unrecorded.
    for (int k = 0; k < es::kInstances; ++k) EXPECT_EQ(f.draws[kQuad0 + k].gaps, 0u) << "quad " << k;
    EXPECT_EQ(f.unrecorded_draws, 0u);
    EXPECT_EQ(f.draws[kLines].gaps, viper::kGapNoMesh);
    EXPECT_EQ(f.draws[kLines].primitive_mode, 2u) << "GL_LINE_LOOP";
    EXPECT_GT(f.draws[kLines].visible_pixels, 0u);
    EXPECT_EQ(f.draws[kRefused].gaps, viper::kGapNoIds | viper::kGapMatrixMissing);
    EXPECT_EQ(f.draws[kRefused].visible_pixels, 0u) << "it wrote no ids";
    // The sky and the particle, drawn without a program: recorded from the fixed-function state
    // (the stack's view re-expressed against the frame's), ids from the id pass.
    for (int k : {kSky, kParticle}) {
      EXPECT_EQ(f.draws[k].program_key, viper::kFixedFunctionProgramKey);
      EXPECT_EQ(f.draws[k].gaps, 0u) << "draw " << k;
      EXPECT_EQ(f.draws[k].view, es::view(f.number)) << "draw " << k;
      EXPECT_GT(f.draws[k].visible_pixels, 0u) << "draw " << k;
    }
    {
      const size_t sky = size_t(0.1 * kHeight) * kWidth + size_t(0.925 * kWidth);
      EXPECT_EQ(f.draw_ids[sky], uint32_t(kSky + 1));
      EXPECT_LT(f.depth_window[sky], 1.0f);
      const size_t refused = size_t(0.1 * kHeight) * kWidth + size_t(0.075 * kWidth);
      EXPECT_EQ(f.draw_ids[refused], 0u) << "the refused quad: drawn there, with depth, no id";
      EXPECT_LT(f.depth_window[refused], 1.0f);
    }

    // The particle in front of quad 0: its depth and its id, not quad 0's. (Also checked by the
    // reprojection below, whose depth bound those pixels would break.)
    {
      const auto [px, py] = pixelOf(0, f.number, 0.5f, 0.5f);
      const size_t i = size_t(py) * kWidth + px;
      EXPECT_EQ(f.draw_ids[i], uint32_t(kParticle + 1)) << "the particle at " << px << "," << py;
      EXPECT_NEAR(f.depth_window[i], 0.05f, 1e-3f) << "the particle's depth (NDC z -0.9)";
    }

    // The hand's and the HUD's pixels: no id of theirs; the capture's color and depth are the
    // scene's (the background there), while the program's own image shows them.
    const auto [hx, hy] = pixelOfEye(Eigen::Vector4f(0.6f, -0.5f, -1.5f, 1.0f));
    const int ox = static_cast<int>((es::kOverlayX + 1) / 2 * kWidth), oy = static_cast<int>((1 - es::kOverlayY) / 2 * kHeight);
    for (const auto& [x, y] : {std::make_pair(hx, hy), std::make_pair(ox, oy)}) {
      const size_t i = size_t(y) * kWidth + x;
      EXPECT_EQ(f.draw_ids[i], 0u) << "at " << x << "," << y;
      EXPECT_EQ(f.depth_window[i], 1.0f) << "the scene's depth (cleared there), not the hand's";
      EXPECT_NEAR(f.color_rgb[i * 3 + 2], 51, 1) << "the clear color (0.1, 0.1, 0.2)";
      if (f.number + 1 == kFrames) {
        const size_t p = (size_t(kHeight - 1 - y) * kWidth + x) * 4;  // the read-back is bottom row first
        EXPECT_GT(static_cast<uint8_t>(r.plain_pixels[p]), 200) << "the program drew its hand and HUD there";
      }
    }
  }
  EXPECT_EQ(all.id_pixels, all.placed_pixels + lines_pixels) << "every id pixel placed but the line loop's";
  EXPECT_GT(all.checked_pixels, 3000u);
  EXPECT_LE(viper::quantile(all.distance_px, 1.0), 0.5f);
  EXPECT_LE(viper::quantile(all.depth_relative, 1.0), 1e-4f);
}
