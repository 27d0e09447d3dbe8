// Runs each scenario of the stress program (gl_stress_program.cpp) plainly, under `capture`, and
// under `capture` with the interceptor built with AddressSanitizer and UndefinedBehaviorSanitizer
// (viper_intercept_asan, asynchronous read-back, three writer threads), and checks that the layer
// never hurts its host: the same exit status, no GL error the program did not cause, the same
// image, a readable stream with a frame per swap, and every draw either recorded right (ids,
// matrices, mesh) or flagged with what could not be recorded (DrawRecord::gaps).
//
// The sanitized interceptor needs the ASan runtime loaded before libc: `capture` sees libasan among
// the interceptor's needed libraries and preloads it first (ASan's own check that it comes first
// stays on here, so the test fails if it does not). In a ThreadSanitizer build of the package
// (scripts/sanitize.sh tsan) the "ASan" run is the build's own TSan interceptor (cmake/capture.cmake)
// and `capture` preloads libtsan the same way. Leak detection is off: Mesa's allocations at exit
// cannot be named (gl_common/sanitizer_options.h).
#include "stress_scene.h"
#include "capture_checks.h"
#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <map>

namespace ss = viper::stress_scene;
using viper::CaptureFrame;
using viper::DrawRecord;
using viper::MeshRegistry;

namespace {

using viper::test::readFile;
using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_capture_stress_"); }

std::string program(const std::string& scenario, const std::string& out) {
  return std::string(VIPER_GL_STRESS_PROGRAM) + " --scenario " + scenario + " --out " + out;
}

enum class Mode { kPlain, kCapture, kCaptureAsanAsync };

struct Result {
  int rc = -1;
  std::string pixels, log;
  std::vector<CaptureFrame> frames;
  MeshRegistry meshes;
  std::string read_error;  ///< the stream could not be read (whole)
  double seconds = 0;
};

Result runScenario(const std::string& scenario, Mode mode) {
  const std::string base = tempDir() + "/" + scenario + "_" + std::to_string(static_cast<int>(mode));
  std::string command;
  if (mode == Mode::kCaptureAsanAsync)
    command = std::string("ASAN_OPTIONS=detect_leaks=0:halt_on_error=1:abort_on_error=0 ") +
              "UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ";
  if (mode != Mode::kPlain) {
    command += std::string(VIPER_CAPTURE_EXE) + " --output " + base + ".vcap --profile " VIPER_STRESS_PROFILE " ";
    if (mode == Mode::kCaptureAsanAsync)
      command += "--library " VIPER_INTERCEPT_ASAN_LIB " --readback async --writer-threads 3 ";
    else
      command += "--readback sync --writer-threads 1 ";
    // Another build of the layer for the synchronous run (to see what an older one did).
    if (mode == Mode::kCapture)
      if (const char* library = std::getenv("VIPER_STRESS_LIBRARY")) command += std::string("--library ") + library + " ";
    command += "-- ";
  }
  command += program(scenario, base + ".rgba") + " > " + base + ".log 2>&1";
  Result r;
  const auto t0 = std::chrono::steady_clock::now();
  r.rc = run(command);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.pixels = readFile(base + ".rgba");
  r.log = readFile(base + ".log");
  if (mode != Mode::kPlain) {
    try {
      viper::test::readCapture(base + ".vcap", r.frames, r.meshes);
    } catch (const std::exception& e) {
      r.read_error = e.what();
    }
  }
  return r;
}

/// What the program drew as object k of a scenario in frame f: the world its vertices went
/// through (the recorded one where the profile can name it), and whether its mesh moves per frame.
struct Expected {
  int objects = 4;
  bool world_recorded = true;   ///< ubo_tbo: the world is in a texture buffer
  bool instanced_mesh = false;  ///< mdi: the mesh is the quad scaled, the world a translation
  bool moving_vertices = false; ///< persistent, threads: vertices at their place, world identity
  int background = 0;           ///< blend_depth: draws before the objects (a background quad)
  int passes = 1;               ///< depth_prepass: the objects drawn in 3 passes; the first has the ids
  uint32_t unrecorded = 0;      ///< fixed_function: a display list a frame
};
Expected expected(const std::string& scenario) {
  Expected e;
  if (scenario == "mdi") e.objects = 8, e.instanced_mesh = true;
  if (scenario == "ubo_tbo") e.world_recorded = false;
  if (scenario == "persistent" || scenario == "threads") e.moving_vertices = true;
  if (scenario == "blend_depth" || scenario == "combined_matrices") e.background = 1;
  if (scenario == "depth_prepass") e.passes = 3;
  if (scenario == "fixed_function") e.unrecorded = 1;
  return e;
}
float shiftOf(const Expected& e, uint64_t frame) { return e.moving_vertices ? ss::frameShift(frame) : 0.0f; }
/// The matrix that takes object k's mesh to where it was drawn.
Eigen::Matrix4f meshToWorld(const Expected& e, int k) {
  if (e.moving_vertices) return Eigen::Matrix4f::Identity();
  if (e.instanced_mesh) {
    Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
    m.block<2, 1>(0, 3) = ss::cellCentre(k);
    return m;
  }
  return ss::world(k);
}

void checkDraw(const Expected& e, const CaptureFrame& f, const DrawRecord& d, const MeshRegistry& meshes) {
  const int n = static_cast<int>(d.index) - e.background;
  const int k = n % e.objects, pass = n / e.objects;  // (depth_prepass: the pass's draw of object k)
  SCOPED_TRACE("draw " + std::to_string(d.index));
  uint32_t owned = 0;
  for (uint32_t id : f.draw_ids) owned += id == d.index + 1;
  EXPECT_EQ(d.visible_pixels, owned);
  if (pass > 0) {
    // Passes after the one that wrote the depth shade its surfaces: they keep its ids.
    EXPECT_EQ(owned, 0u) << "a pass at equal depth took ids from the depth pre-pass";
  } else if (!(d.gaps & viper::kGapNoIds)) {
    EXPECT_EQ(f.draw_ids[ss::centrePixel(k)], d.index + 1);
    EXPECT_GT(d.visible_pixels, 0u);
  }
  if (!(d.gaps & viper::kGapMatrixMissing)) {
    const uint8_t flags = viper::kHasView | viper::kHasProjection | (e.world_recorded ? viper::kHasWorld : 0);
    EXPECT_EQ(d.matrix_flags, flags);
    EXPECT_TRUE(d.view.isApprox(ss::view(f.number), 1e-6f)) << d.view;
    EXPECT_TRUE(d.projection.isApprox(ss::projection(), 1e-6f)) << d.projection;
    if (e.world_recorded) {
      EXPECT_TRUE(d.world.isApprox(meshToWorld(e, k), 1e-6f)) << d.world;
    }
  }
  if (!(d.gaps & viper::kGapNoMesh)) {
    ASSERT_NE(d.mesh_key, 0u);
    const viper::MeshRecord* mesh = meshes.find(d.mesh_key);
    ASSERT_NE(mesh, nullptr);
    EXPECT_EQ(mesh->indices.size(), 6u);
    // Every vertex lies on a corner of the object's quad, as this frame drew it.
    const Eigen::Vector2f c = ss::cellCentre(k, shiftOf(e, f.number));
    for (size_t v = 0; v + 2 < mesh->positions_xyz.size(); v += 3) {
      const Eigen::Vector4f p =
          meshToWorld(e, k) * Eigen::Vector4f(mesh->positions_xyz[v], mesh->positions_xyz[v + 1], mesh->positions_xyz[v + 2], 1);
      EXPECT_NEAR(std::abs(p.x() - c.x()), ss::kHalf, 1e-5f) << "vertex " << v / 3 << " frame " << f.number;
      EXPECT_NEAR(std::abs(p.y() - c.y()), ss::kHalf, 1e-5f) << "vertex " << v / 3 << " frame " << f.number;
    }
  }
}

// blend_depth: the background (draw 0) holds its own plane's depth wherever it has the id; the
// objects' mostly transparent parts (blended, depth written) hold the object's depth and id 0.
void checkIdsFollowDepth(const CaptureFrame& f) {
  ASSERT_EQ(f.depth_window.size(), size_t(ss::kSize) * ss::kSize);
  const float background_depth = f.depth_window[size_t(ss::kSize - 4) * ss::kSize + ss::kSize / 2];  // below the objects
  ASSERT_EQ(f.draw_ids[size_t(ss::kSize - 4) * ss::kSize + ss::kSize / 2], 1u);
  size_t background_nearer = 0, veiled = 0;
  for (size_t px = 0; px < f.draw_ids.size(); ++px) {
    const bool nearer = f.depth_window[px] < background_depth - 1e-4f && f.depth_window[px] > 0.0f;
    if (f.draw_ids[px] == 1 && std::abs(f.depth_window[px] - background_depth) > 1e-4f) ++background_nearer;
    if (f.draw_ids[px] == 0 && nearer) ++veiled;
  }
  EXPECT_EQ(background_nearer, 0u) << "pixels with the background's id and another surface's depth";
  // Each object's transparent part: 0.3 of its width over its height (a quad is 2 kHalf * 32 px
  // wide and high), at least half of that in pixel centres.
  const double part = 0.3 * (2 * ss::kHalf * 32) * (2 * ss::kHalf * 32);
  EXPECT_GE(veiled, size_t(0.5 * 4 * part)) << "transparent parts with depth and id 0";
}

// The lines of a log that begin with `prefix`, in order.
std::vector<std::string> linesStartingWith(const std::string& log, const std::string& prefix) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < log.size()) {
    size_t end = log.find('\n', start);
    if (end == std::string::npos) end = log.size();
    if (log.compare(start, prefix.size(), prefix) == 0) lines.push_back(log.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

void checkCapture(const std::string& scenario, bool async, const Result& plain, const Result& r) {
  EXPECT_EQ(r.rc, plain.rc) << r.log;
  // What the program learned of its window (window_queries): the same answers as without the layer.
  EXPECT_EQ(linesStartingWith(r.log, "window:"), linesStartingWith(plain.log, "window:"));
  // What its queries counted (fixed_function) and what it learned of its uniforms (ubo_tbo): the
  // same as without the layer.
  EXPECT_EQ(linesStartingWith(r.log, "query:"), linesStartingWith(plain.log, "query:"));
  EXPECT_EQ(linesStartingWith(r.log, "introspect:"), linesStartingWith(plain.log, "introspect:"));
  EXPECT_EQ(r.read_error, "") << r.log;
  EXPECT_EQ(r.log.find("GL error"), std::string::npos) << r.log;
  EXPECT_EQ(r.log.find("Sanitizer"), std::string::npos) << r.log;
  EXPECT_EQ(r.log.find("runtime error"), std::string::npos) << r.log;
  ASSERT_EQ(r.pixels.size(), plain.pixels.size());
  size_t differ = 0;
  for (size_t i = 0; i < r.pixels.size(); ++i) differ += r.pixels[i] != plain.pixels[i];
  EXPECT_EQ(differ, 0u) << "bytes of the program's own image changed under capture";

  const Expected e = expected(scenario);
  // A frame per swap. exit_thread with asynchronous read-back: the frame still in the GL's buffers
  // when another thread ends the program cannot be read there (its context is current on the
  // render thread), and the layer says so.
  const bool lost_one = r.log.find("1 frames read asynchronously were lost") != std::string::npos;
  EXPECT_EQ(lost_one, scenario == "exit_thread" && async) << r.log;
  EXPECT_EQ(r.frames.size(), size_t(ss::kFrames) - (lost_one ? 1 : 0));
  for (const CaptureFrame& f : r.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    EXPECT_EQ(viper::validateFrame(f), "");
    ASSERT_EQ(f.width, uint32_t(ss::kSize));
    EXPECT_EQ(f.draws.size(), size_t(e.objects * e.passes + e.background));
    EXPECT_EQ(f.unrecorded_draws, e.unrecorded);
    for (const DrawRecord& d : f.draws)
      if (static_cast<int>(d.index) >= e.background) checkDraw(e, f, d, r.meshes);
    if (scenario == "blend_depth") checkIdsFollowDepth(f);
    if (scenario == "combined_matrices") {  // the background: world space, so world = identity
      const DrawRecord& b = f.draws[0];
      EXPECT_EQ(b.matrix_flags, viper::kHasWorld | viper::kHasView | viper::kHasProjection);
      EXPECT_TRUE(b.world.isIdentity(1e-6f)) << b.world;
      EXPECT_TRUE(b.view.isApprox(ss::view(f.number), 1e-6f)) << b.view;
    }
    // The stream's colour is the program's image (its read-back is bottom row first, RGBA).
    if (f.number == ss::kFrames - 1) {
      size_t colour_diffs = 0;
      for (int y = 0; y < ss::kSize; ++y)
        for (int x = 0; x < ss::kSize; ++x)
          for (int c = 0; c < 3; ++c)
            colour_diffs += f.color_rgb[(size_t(y) * ss::kSize + x) * 3 + c] !=
                            static_cast<uint8_t>(plain.pixels[(size_t(ss::kSize - 1 - y) * ss::kSize + x) * 4 + c]);
      EXPECT_EQ(colour_diffs, 0u);
    }
  }
}

class Stress : public ::testing::TestWithParam<std::string> {};

TEST_P(Stress, RunsAsWithoutCaptureAndRecordsOrFlagsEveryDraw) {
  const std::string scenario = GetParam();
  const Result plain = runScenario(scenario, Mode::kPlain);
  ASSERT_EQ(plain.rc, 0) << plain.log;
  ASSERT_EQ(plain.pixels.size(), size_t(ss::kSize) * ss::kSize * 4);
  if (scenario == "window_queries") {
    ASSERT_EQ(linesStartingWith(plain.log, "window:").size(), size_t(ss::kFrames) + 1);
  }
  if (scenario == "ubo_tbo") {
    ASSERT_EQ(linesStartingWith(plain.log, "introspect:").size(), 1u);
  }
  {
    SCOPED_TRACE("capture, synchronous read-back");
    const Result r = runScenario(scenario, Mode::kCapture);
    checkCapture(scenario, false, plain, r);
    std::printf("%s: plain %.2f s, captured %.2f s\n", scenario.c_str(), plain.seconds, r.seconds);
  }
  {
    SCOPED_TRACE("capture under ASan, asynchronous read-back, 3 writer threads");
    const Result r = runScenario(scenario, Mode::kCaptureAsanAsync);
    checkCapture(scenario, true, plain, r);
    std::printf("%s: captured under ASan %.2f s\n", scenario.c_str(), r.seconds);
  }
}

// --start-on-scene waits for a frame with the camera's view and projection: with combined
// matrices only (no draw gives the view itself), the frame's recovered camera starts it.
TEST(StressCombinedMatrices, StartOnSceneStartsAtTheFirstFrameWithARecoveredCamera) {
  const std::string base = tempDir() + "/start_on_scene";
  const std::string log = base + ".log";
  ASSERT_EQ(run(std::string(VIPER_CAPTURE_EXE) + " --output " + base + ".vcap --profile " VIPER_STRESS_PROFILE
                " --start-on-scene -- " + program("combined_matrices", base + ".rgba") + " > " + log + " 2>&1"),
            0)
      << readFile(log);
  std::vector<CaptureFrame> frames;
  MeshRegistry meshes;
  viper::test::readCapture(base + ".vcap", frames, meshes);
  ASSERT_EQ(frames.size(), size_t(ss::kFrames)) << readFile(log);
  EXPECT_EQ(frames[0].number, 0u);
  EXPECT_NE(readFile(log).find("the frame's camera from combined matrices: view: projection⁻¹ · view-projection; "
                               "projection: given"),
            std::string::npos)
      << readFile(log);
}

// The sanitized interceptor's exported dlsym is called by the sanitizer runtime's own start
// (dlsym(RTLD_NEXT, ...) for every function it intercepts), before the runtime can run instrumented
// code or its interceptors: it must answer without either, wherever the runtime comes in the
// program's libraries. Preloaded alone into a program that is not instrumented (the runtime then
// comes after libc, loaded as the interceptor's dependency; ASan's check that it comes first is
// off for this), and through `capture`, which preloads the runtime first.
TEST(SanitizedInterceptor, StartsInAProgramWithoutGl) {
  const std::string options = "ASAN_OPTIONS=detect_leaks=0:halt_on_error=1:abort_on_error=0:verify_asan_link_order=0 ";
  EXPECT_EQ(run(options + "LD_PRELOAD=" VIPER_INTERCEPT_ASAN_LIB " /bin/true"), 0);
  const std::string out = tempDir() + "/true.vcap";
  EXPECT_EQ(run("ASAN_OPTIONS=detect_leaks=0:halt_on_error=1 " VIPER_CAPTURE_EXE " --output " + out +
                " --library " VIPER_INTERCEPT_ASAN_LIB " -- /bin/true"),
            0);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, Stress,
                         ::testing::Values("mdi", "persistent", "ubo_tbo", "binary", "threads", "destroy",
                                           "exit_thread", "blend_depth", "window_queries", "extension_names",
                                           "depth_prepass", "fixed_function", "combined_matrices"));

}  // namespace
