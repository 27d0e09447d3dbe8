// Runs the engine-style GL test program (gl_engine_program.cpp) plainly and under `capture`, and
// checks the capture against what the program knows it drew (engine_scene.h): every instance of
// the instanced draw its own draw, id and world matrix (from attributes in a persistent mapping),
// view and projection from the uniform block, the G-buffer's normals (draw buffer 1) left alone,
// the 2D overlay neither recorded nor in the capture's color, glProgramBinary refused, and the
// program's own output unchanged.
#include "engine_scene.h"
#include "capture_checks.h"
#include "../common/process_util.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace es = viper::engine_scene;
using viper::CaptureFrame;

namespace {

constexpr int kWidth = 160, kHeight = 120, kFrames = 4;

using viper::test::readFile;
using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_engine_test_"); }

struct EngineRun {
  int plain_rc = -1, capture_rc = -1;
  std::string plain_pixels, captured_pixels, plain_stdout, captured_stdout;
  std::vector<CaptureFrame> frames;
  viper::MeshRegistry meshes;
};

const EngineRun& runEngine(int offscreen, int indirect = 0) {
  static std::map<int, EngineRun> runs;
  auto it = runs.find(offscreen * 2 + indirect);
  if (it != runs.end()) return it->second;
  EngineRun& r = runs[offscreen * 2 + indirect];
  const std::string d = tempDir() + "/offscreen" + std::to_string(offscreen) + "_indirect" + std::to_string(indirect);
  const std::string program = std::string(VIPER_GL_ENGINE_PROGRAM) + " --frames " + std::to_string(kFrames) +
                              " --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight) + " --offscreen " +
                              std::to_string(offscreen) + " --indirect " + std::to_string(indirect) + " --out ";
  r.plain_rc = run(program + d + "_plain.rgba > " + d + "_plain.txt");
  r.capture_rc = run(std::string(VIPER_CAPTURE_EXE) + " --output " + d + ".vcap --profile " VIPER_ENGINE_PROFILE " -- " +
                     program + d + "_captured.rgba > " + d + "_captured.txt");
  r.plain_pixels = readFile(d + "_plain.rgba");
  r.captured_pixels = readFile(d + "_captured.rgba");
  r.plain_stdout = readFile(d + "_plain.txt");
  r.captured_stdout = readFile(d + "_captured.txt");
  if (r.capture_rc == 0) {
    viper::test::readCapture(d + ".vcap", r.frames, r.meshes);
  }
  return r;
}

// Pixel (column, row from the top) where a point of an instance's quad lands.
std::pair<int, int> pixelOf(int instance, uint64_t frame, float x, float y) {
  const Eigen::Vector4f c = es::projection() * es::view(frame) * es::world(instance, frame) * Eigen::Vector4f(x, y, 0, 1);
  return {static_cast<int>((c.x() / c.w() + 1) / 2 * kWidth), static_cast<int>((1 - c.y() / c.w()) / 2 * kHeight)};
}

void checkEngineRun(const EngineRun& r, size_t composite_draws) {
  ASSERT_EQ(r.plain_rc, 0);
  ASSERT_EQ(r.capture_rc, 0);
  ASSERT_EQ(r.plain_pixels.size(), size_t(kWidth) * kHeight * 4);
  EXPECT_TRUE(r.plain_pixels == r.captured_pixels) << "the program's own output changed under capture";
  EXPECT_NE(r.captured_stdout.find("binary_formats=0"), std::string::npos)
      << "program binaries are refused, so that every program links from (rewritten) source";
  ASSERT_EQ(r.frames.size(), size_t(kFrames));

  viper::ReprojectionCheck all;
  for (const CaptureFrame& f : r.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    EXPECT_EQ(viper::validateFrame(f), "");
    // One draw per instance (the overlay is not recorded; the composite pass, if any, comes last).
    ASSERT_EQ(f.draws.size(), size_t(es::kInstances) + composite_draws);
    for (int k = 0; k < es::kInstances; ++k) {
      const viper::DrawRecord& d = f.draws[k];
      ASSERT_EQ(d.matrix_flags, viper::kHasWorld | viper::kHasView | viper::kHasProjection) << "instance " << k;
      EXPECT_TRUE(d.world.isApprox(es::world(k, f.number), 1e-5f)) << "instance " << k << "\n" << d.world;
      EXPECT_EQ(d.view, es::view(f.number));
      EXPECT_EQ(d.projection, es::projection());
      EXPECT_EQ(d.mesh_key, f.draws[0].mesh_key) << "one mesh, three instances";
      EXPECT_EQ(d.primitive_count, 2u);
      EXPECT_GT(d.visible_pixels, 100u);
      // The instance's centre carries its own id.
      const auto [x, y] = pixelOf(k, f.number, 0.0f, 0.0f);
      ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight);
      EXPECT_EQ(f.draw_ids[size_t(y) * kWidth + x], uint32_t(k + 1)) << "instance " << k;
    }
    all.add(viper::checkReprojection(f, r.meshes));

    // The overlay quad: in the program's image (last frame), not in the capture's color.
    const int ox = static_cast<int>((es::kOverlayX + 1) / 2 * kWidth), oy = static_cast<int>((1 - es::kOverlayY) / 2 * kHeight);
    const size_t o = size_t(oy) * kWidth + ox;
    EXPECT_EQ(f.draw_ids[o], 0u) << "no id under the overlay (nothing else there)";
    if (f.number + 1 == kFrames) {
      const size_t p = (size_t(kHeight - 1 - oy) * kWidth + ox) * 4;  // the read-back is bottom row first
      EXPECT_EQ(static_cast<uint8_t>(r.plain_pixels[p]), 255);
      EXPECT_EQ(static_cast<uint8_t>(r.plain_pixels[p + 1]), 230);
      EXPECT_NE(f.color_rgb[o * 3 + 1], 230) << "the capture's color is the scene before the overlay";
    }
  }
  EXPECT_EQ(all.id_pixels, all.placed_pixels);
  EXPECT_GT(all.checked_pixels, 3000u);
  EXPECT_LE(viper::quantile(all.distance_px, 1.0), 0.5f);
  EXPECT_LE(viper::quantile(all.depth_relative, 1.0), 1e-4f);
}

}  // namespace

TEST(CaptureEngine, InstancesUniformBlockPersistentMapOverlayIntoTheWindow) { checkEngineRun(runEngine(0), 0); }

TEST(CaptureEngine, GBufferKeepsItsNormalsAndGivesIds) {
  // The composite (color and normals of the G-buffer, half each) is the program's output: a
  // capture that wrote over draw buffer 1 would change it. The composite pass draws into the
  // default framebuffer after the scene and is recorded last, owning no pixel.
  const EngineRun& r = runEngine(1);
  checkEngineRun(r, 1);
  for (const CaptureFrame& f : r.frames) EXPECT_EQ(f.draws.back().visible_pixels, 0u);
}

TEST(CaptureEngine, MultiDrawIndirectIsRecordedAsItsInstances) {
  // glMultiDrawElementsIndirect with two commands (instances 0-1, instance 2): the same three draws.
  checkEngineRun(runEngine(0, 1), 0);
  EXPECT_TRUE(runEngine(0, 1).plain_pixels == runEngine(0, 0).plain_pixels) << "the indirect program draws the same";
}

TEST(CaptureEngine, WithoutCaptureProgramBinariesAreOffered) {
  // The refusal above is the layer's: the driver offers binary formats to the plain program.
  const EngineRun& r = runEngine(0);
  EXPECT_EQ(r.plain_stdout.find("binary_formats=0"), std::string::npos) << r.plain_stdout;
}
