// Runs the GL test program plainly and under `capture`, and checks the capture stream against
// what the program knows it drew (test_scene_layout.h): ids, primitive ids, transparency,
// matrices, meshes, deformed vertices, depth, and that the program's own output is unchanged.
#include "test_scene_layout.h"
#include "../common/process_util.h"
#include "viper/capture/capture_stream.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace ts = viper::test_scene;
using viper::CaptureFrame;
using viper::CaptureReader;
using viper::MeshRecord;

namespace {

constexpr int kWidth = 160, kHeight = 120, kFrames = 3;

using viper::test::readFile;
using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_capture_test_"); }

std::vector<CaptureFrame> readFrames(const std::string& path) {
  std::vector<CaptureFrame> frames;
  CaptureReader reader(path);
  CaptureFrame f;
  while (reader.next(f) == CaptureReader::Status::kFrame) frames.push_back(f);
  return frames;
}

std::string program(const std::string& mode, const std::string& out, int frames = kFrames,
                    const std::string& args = "") {
  return std::string(VIPER_GL_TEST_PROGRAM) + " --mode " + mode + " --frames " + std::to_string(frames) +
         " --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight) + " --out " + out + args;
}

std::string capture(const std::string& vcap, const std::string& extra = "") {
  return std::string(VIPER_CAPTURE_EXE) + " --output " + vcap + " --profile " VIPER_PROFILE_DIR
         "/viper_scene.yaml --condition rain " + extra + " -- ";
}

// Pixel (column, row from top) where a point of a draw's object space lands.
struct Pixel {
  int x, y;
};
Eigen::Vector4f clip(uint32_t draw, uint64_t frame, const Eigen::Vector4f& object) {
  return ts::projection() * ts::view() * ts::world(draw, frame) * object;
}
Pixel pixelOf(uint32_t draw, uint64_t frame, float x, float y) {
  const Eigen::Vector4f c = clip(draw, frame, Eigen::Vector4f(x, y, 0, 1));
  return Pixel{static_cast<int>((c.x() / c.w() + 1) / 2 * kWidth), static_cast<int>((1 - c.y() / c.w()) / 2 * kHeight)};
}
size_t at(const Pixel& p) { return static_cast<size_t>(p.y) * kWidth + p.x; }

// Runs a mode (with extra program arguments) plainly and captured once per test binary run;
// shares the results.
struct ModeRun {
  int plain_rc = -1, capture_rc = -1;
  std::string plain_pixels, captured_pixels;
  std::vector<CaptureFrame> frames;
};
const ModeRun& runMode(const std::string& mode, const std::string& wrapper = "", const std::string& args = "") {
  static std::map<std::string, ModeRun> runs;
  auto it = runs.find(mode + args);
  if (it != runs.end()) return it->second;
  ModeRun& r = runs[mode + args];
  const std::string d = tempDir() + "/" + mode + (args.empty() ? "" : "_args" + std::to_string(runs.size()));
  r.plain_rc = run(wrapper + program(mode, d + "_plain.rgba", kFrames, args));
  r.capture_rc = run(wrapper + capture(d + ".vcap") + program(mode, d + "_captured.rgba", kFrames, args));
  r.plain_pixels = readFile(d + "_plain.rgba");
  r.captured_pixels = readFile(d + "_captured.rgba");
  if (r.capture_rc == 0) r.frames = readFrames(d + ".vcap");
  return r;
}

// `extra_draws`: draws after the scene's (a composite pass), which must own no pixel.
void checkRun(const ModeRun& r, uint32_t extra_draws = 0) {
  ASSERT_EQ(r.plain_rc, 0);
  ASSERT_EQ(r.capture_rc, 0);
  ASSERT_EQ(r.plain_pixels.size(), size_t(kWidth) * kHeight * 4);
  EXPECT_TRUE(r.plain_pixels == r.captured_pixels) << "the program's own output changed under capture";
  ASSERT_EQ(r.frames.size(), size_t(kFrames));

  // The stream's color is the program's image (its own read-back is bottom row first, RGBA).
  const CaptureFrame& last = r.frames.back();
  size_t color_diffs = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 3; ++c)
        color_diffs += last.color_rgb[(size_t(y) * kWidth + x) * 3 + c] !=
                       static_cast<uint8_t>(r.plain_pixels[(size_t(kHeight - 1 - y) * kWidth + x) * 4 + c]);
  EXPECT_EQ(color_diffs, 0u);

  for (const CaptureFrame& f : r.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    EXPECT_EQ(viper::validateFrame(f), "");
    EXPECT_EQ(f.condition, "rain");
    ASSERT_EQ(f.width, uint32_t(kWidth));
    ASSERT_EQ(f.draws.size(), size_t(ts::kDrawCount + extra_draws));
    for (uint32_t d = ts::kDrawCount; d < f.draws.size(); ++d) EXPECT_EQ(f.draws[d].visible_pixels, 0u) << d;
    // Draw ids where the program drew, and not where only the transparent glass is.
    EXPECT_EQ(f.draw_ids[at(pixelOf(ts::kQuad, f.number, -0.5f, 0.6f))], ts::kQuad + 1);
    EXPECT_EQ(f.draw_ids[at(pixelOf(ts::kTriangle, f.number, 0.0f, -0.7f))], ts::kTriangle + 1);
    EXPECT_EQ(f.draw_ids[at(pixelOf(ts::kSkinned, f.number, 0.0f, 0.2f))], ts::kSkinned + 1);
    EXPECT_EQ(f.draw_ids[at(Pixel{kWidth - 2, 1})], 0u);
    const Pixel glass_over_quad = pixelOf(ts::kGlass, f.number, -0.5f, 0.0f);
    const Pixel glass_over_nothing = pixelOf(ts::kGlass, f.number, 0.0f, 0.0f);
    EXPECT_EQ(f.draw_ids[at(glass_over_quad)], ts::kQuad + 1);
    EXPECT_EQ(f.draw_ids[at(glass_over_nothing)], 0u);
    const Pixel quad_plain = pixelOf(ts::kQuad, f.number, -0.6f, 0.7f);
    EXPECT_NE(f.color_rgb[at(glass_over_quad) * 3 + 2], f.color_rgb[at(quad_plain) * 3 + 2]) << "glass not drawn";
    // Primitive ids: triangle 0 of the quad is its lower-right half, triangle 1 the upper-left.
    EXPECT_EQ(f.primitive_ids[at(pixelOf(ts::kQuad, f.number, 0.6f, -0.7f))], 0u);
    EXPECT_EQ(f.primitive_ids[at(pixelOf(ts::kQuad, f.number, -0.6f, 0.7f))], 1u);
    // Depth of the quad (window depth of z = 0 in its object space).
    const Eigen::Vector4f c = clip(ts::kQuad, f.number, Eigen::Vector4f(-0.6f, 0.7f, 0, 1));
    EXPECT_NEAR(f.depth_window[at(quad_plain)], 0.5f * c.z() / c.w() + 0.5f, 1e-5);

    const uint32_t expected_primitives[4] = {2, 1, 2, 8};
    for (uint32_t d = 0; d < ts::kDrawCount; ++d) {
      SCOPED_TRACE("draw " + std::to_string(d));
      const viper::DrawRecord& rec = f.draws[d];
      EXPECT_EQ(rec.index, d);
      EXPECT_EQ(rec.matrix_flags, viper::kHasWorld | viper::kHasView | viper::kHasProjection);
      EXPECT_EQ(rec.world, ts::world(d, f.number));
      EXPECT_EQ(rec.view, ts::view());
      EXPECT_EQ(rec.projection, ts::projection());
      EXPECT_EQ(rec.primitive_count, expected_primitives[d]);
      EXPECT_NE(rec.mesh_key, 0u);
      EXPECT_NE(rec.program_key, 0u);
      EXPECT_NE(rec.vertex_buffer_key, 0u);
      uint32_t owned = 0;
      for (uint32_t id : f.draw_ids) owned += id == d + 1;
      EXPECT_EQ(rec.visible_pixels, owned);
      if (d != ts::kGlass) {
        EXPECT_GT(rec.visible_pixels, 0u);
      }
      EXPECT_EQ(rec.deformed_clip_xyzw.empty(), d != ts::kSkinned);
    }
    EXPECT_EQ(f.draws[ts::kQuad].program_key, f.draws[ts::kTriangle].program_key);
    EXPECT_NE(f.draws[ts::kQuad].program_key, f.draws[ts::kGlass].program_key);
    EXPECT_EQ(f.draws[ts::kGlass].visible_pixels, 0u);
    // Textures: only the glass samples one (its 2x2 tint); the key names its content.
    EXPECT_TRUE(f.draws[ts::kQuad].texture_keys.empty());
    ASSERT_EQ(f.draws[ts::kGlass].texture_keys.size(), 1u);
    EXPECT_NE(f.draws[ts::kGlass].texture_keys[0], 0u);
    EXPECT_EQ(f.draws[ts::kGlass].texture_keys, r.frames[0].draws[ts::kGlass].texture_keys);

    // Deformed vertices: what the program's skinning gives, in clip space, in mesh vertex order.
    const std::vector<float> strip = ts::skinnedVertices();
    const std::vector<float>& deformed = f.draws[ts::kSkinned].deformed_clip_xyzw;
    ASSERT_EQ(deformed.size(), 10u * 4);
    for (int v = 0; v < 10; ++v) {
      const float* s = &strip[(ts::kSkinPadding + v) * 4];
      const Eigen::Vector4f expected = ts::projection() * ts::view() * ts::world(ts::kSkinned, f.number) *
                                       ts::skinned(Eigen::Vector3f(s[0], s[1], s[2]), s[3], f.number);
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(deformed[v * 4 + k], expected[k], 1e-5) << "vertex " << v;
    }
  }

  // Mesh store: sent once, in the first frame, with object-space positions.
  EXPECT_EQ(r.frames[0].new_meshes.size(), 4u);
  for (size_t i = 1; i < r.frames.size(); ++i) EXPECT_TRUE(r.frames[i].new_meshes.empty());
  std::map<uint64_t, MeshRecord> store;
  for (const MeshRecord& m : r.frames[0].new_meshes) store[m.key] = m;
  const MeshRecord& quad = store[r.frames[0].draws[ts::kQuad].mesh_key];
  EXPECT_EQ(quad.positions_xyz, ts::quadVertices());
  EXPECT_EQ(quad.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(store[r.frames[0].draws[ts::kTriangle].mesh_key].positions_xyz, ts::triangleVertices());
  const MeshRecord& skinned = store[r.frames[0].draws[ts::kSkinned].mesh_key];
  EXPECT_EQ(skinned.indices, ts::skinnedIndices());
  ASSERT_EQ(skinned.positions_xyz.size(), 30u);
  const std::vector<float> strip = ts::skinnedVertices();
  for (int v = 0; v < 10; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(skinned.positions_xyz[v * 3 + k], strip[(ts::kSkinPadding + v) * 4 + k]);
}

}  // namespace

TEST(CaptureRun, LinkedGl) { checkRun(runMode("direct")); }
TEST(CaptureRun, EglGetProcAddress) { checkRun(runMode("eglproc")); }
TEST(CaptureRun, DlopenedEgl) { checkRun(runMode("dlopen")); }

// A program that renders its scene into a framebuffer object of its own and composites it into the
// default framebuffer with a post effect: ids and depth are the scene's, exactly as when it renders
// straight into the default framebuffer; the color is its final (inverted) image.
static void checkOffscreen(const std::string& offscreen_arg) {
  const ModeRun& offscreen = runMode("direct", "", " --offscreen " + offscreen_arg);
  checkRun(offscreen, /*extra_draws=*/1);
  const ModeRun& direct = runMode("direct");
  ASSERT_EQ(offscreen.frames.size(), direct.frames.size());
  for (size_t i = 0; i < direct.frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const CaptureFrame &a = offscreen.frames[i], &b = direct.frames[i];
    EXPECT_TRUE(a.draw_ids == b.draw_ids);
    EXPECT_TRUE(a.primitive_ids == b.primitive_ids);
    EXPECT_TRUE(a.depth_window == b.depth_window);
    ASSERT_EQ(a.color_rgb.size(), b.color_rgb.size());
    size_t not_inverted = 0;
    for (size_t k = 0; k < a.color_rgb.size(); ++k) not_inverted += a.color_rgb[k] != 255 - b.color_rgb[k];
    EXPECT_EQ(not_inverted, 0u) << "the captured color is not the composite";
  }
}

TEST(CaptureRun, SceneRenderedOffscreenAndComposited) { checkOffscreen("1"); }
// With a depth texture, after a shadow pass into a smaller depth-only framebuffer object, whose
// draws are not the scene's and stay out of the draw list (checkRun counts the draws).
TEST(CaptureRun, SceneInADepthTextureFramebufferAfterAShadowPass) { checkOffscreen("2"); }

TEST(CaptureRun, GlxUnderXvfb) {
  if (run("command -v xvfb-run > /dev/null") != 0) GTEST_SKIP() << "xvfb-run not installed";
  checkRun(runMode("glx", "xvfb-run -a -s '-screen 0 320x240x24' "));
}

TEST(CaptureRun, FrameLimitStopsTheProgramWithACompleteStream) {
  const std::string d = tempDir() + "/limit";
  ASSERT_EQ(run(capture(d + ".vcap", "--frames 2") + program("direct", d + ".rgba", 50)), 0);
  EXPECT_EQ(readFrames(d + ".vcap").size(), 2u);
}

// Several writer threads finish and compress frames side by side and append them in order: the
// stream is byte for byte the one a single thread writes (stamps from --fps, so runs agree), and
// a full disk under several threads still keeps every frame before the failure (below).
TEST(CaptureRun, ParallelWritersWriteTheSameStream) {
  const std::string d = tempDir() + "/writers";
  const int frames = 24;
  ASSERT_EQ(run(capture(d + "_1.vcap", "--fps 15 --writer-threads 1") + program("direct", d + "_1.rgba", frames)), 0);
  ASSERT_EQ(run(capture(d + "_4.vcap", "--fps 15 --writer-threads 4") + program("direct", d + "_4.rgba", frames)), 0);
  const std::string one = readFile(d + "_1.vcap"), four = readFile(d + "_4.vcap");
  ASSERT_EQ(readFrames(d + "_4.vcap").size(), size_t(frames));
  EXPECT_TRUE(one == four) << one.size() << " bytes with one thread, " << four.size() << " with four";
  EXPECT_NE(run(capture(d + "_0.vcap", "--writer-threads 0") + " true 2> /dev/null"), 0);
}

// Asynchronous read-back (frames read into persistently mapped pixel-pack buffers, handed over
// at the next swap) gives the stream synchronous read-back gives: the scene in the default
// framebuffer, in the program's framebuffer objects (--offscreen 1|2), the last frame at exit,
// and with a frame limit.
TEST(CaptureRun, AsynchronousReadBackWritesTheSameStream) {
  const std::string d = tempDir() + "/readback";
  int k = 0;
  for (const std::string args : {"", " --offscreen 1", " --offscreen 2"}) {
    for (const std::string limit : {"", " --frames 4"}) {
      const std::string base = d + std::to_string(k++);
      const std::string opts = "--fps 15 --writer-threads 2" + limit;
      ASSERT_EQ(run(capture(base + "_sync.vcap", opts + " --readback sync") +
                    program("dlopen", base + "_sync.rgba", 12, args)), 0);
      ASSERT_EQ(run(capture(base + "_async.vcap", opts + " --readback async") +
                    program("dlopen", base + "_async.rgba", 12, args)), 0);
      ASSERT_EQ(readFrames(base + "_async.vcap").size(), limit.empty() ? 12u : 4u) << args << limit;
      EXPECT_TRUE(readFile(base + "_sync.vcap") == readFile(base + "_async.vcap")) << args << limit;
    }
  }
  EXPECT_NE(run(capture(d + "_bad.vcap", "--readback later") + " true 2> /dev/null"), 0);
}

TEST(CaptureRun, ForwardsExitCodeAndRejectsBadProfiles) {
  const std::string d = tempDir() + "/misc";
  EXPECT_EQ(run(std::string(VIPER_CAPTURE_EXE) + " --output " + d + ".vcap -- sh -c 'exit 3'"), 3);
  std::ofstream(d + "_bad.yaml") << "programs:\n  - wrold: uWorld\n";
  EXPECT_EQ(run(std::string(VIPER_CAPTURE_EXE) + " --output " + d + ".vcap --profile " + d + "_bad.yaml -- true 2> " +
                d + "_err.txt"),
            2);
  EXPECT_NE(readFile(d + "_err.txt").find(d + "_bad.yaml:2"), std::string::npos) << readFile(d + "_err.txt");
  EXPECT_NE(run(std::string(VIPER_CAPTURE_EXE) + " -- true 2> /dev/null"), 0);  // --output missing
}

// A full disk (a file-size limit, SIGXFSZ ignored) while the program runs: the program runs to its
// end undisturbed (exit 0; its own output goes to /dev/null, which the limit does not cover), the stream keeps every frame written before the one that did not fit, and
// capture exits 74 (EX_IOERR) naming the file, so the capture is not taken for a complete one.
TEST(CaptureRun, AFullDiskStopsTheCaptureNotTheProgram) {
  const std::string d = tempDir() + "/full";
  const int frames = 30;
  ASSERT_EQ(run(capture(d + "_whole.vcap") + program("direct", d + "_whole.rgba", frames)), 0);
  const auto whole = readFrames(d + "_whole.vcap");
  ASSERT_EQ(whole.size(), size_t(frames));
  const std::string bytes = readFile(d + "_whole.vcap");
  const std::string limit = std::to_string(bytes.size() / 2 / 1024);  // KiB: about half the frames
  const int rc = run("sh -c \"trap '' XFSZ; ulimit -f " + limit + "; exec " + capture(d + ".vcap", "--writer-threads 3") +
                     program("direct", "/dev/null", frames) + "\" 2> " + d + "_err.txt");
  const std::string err = readFile(d + "_err.txt");
  EXPECT_EQ(rc, 74) << "74 only when the program itself exited 0: " << err;
  EXPECT_NE(err.find("capture: " + d + ".vcap: writing frame"), std::string::npos) << err;
  EXPECT_NE(err.find("File too large"), std::string::npos) << err;
  // The frames before the failure read back whole, then the damage is reported.
  std::vector<CaptureFrame> kept;
  CaptureReader reader(d + ".vcap");
  CaptureFrame f;
  EXPECT_THROW(
      {
        while (reader.next(f) == CaptureReader::Status::kFrame) kept.push_back(f);
      },
      viper::CaptureFormatError);
  ASSERT_GT(kept.size(), 0u);
  EXPECT_LT(kept.size(), size_t(frames));
  for (size_t i = 0; i < kept.size(); ++i) EXPECT_TRUE(kept[i].color_rgb == whole[i].color_rgb) << "frame " << i;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
