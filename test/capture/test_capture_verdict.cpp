// `capture`'s verdict and --require-ids, and capture_check's judged checks, on captures whose truth
// is known: the fixed-function program (nothing recorded), the test program with its profile
// (everything), without a profile (nothing placed), with no frame written; the test scene's capture
// (perspective, moving: every check runs) as it is, and with its world matrices moved through the
// stream writer (reprojection and flow wrong).
#include "../common/process_util.h"
#include "capture_checks.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/capture_verdict.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

using viper::CaptureFrame;
using viper::CaptureReader;

namespace {

using viper::test::readFile;
using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_capture_verdict_"); }

constexpr int kMostlyEmpty = 65;  // capture's exit status when --require-ids is not met
constexpr int kCheckFailed = 3, kNothingChecked = 4;  // capture_check's

struct Result {
  int rc = -1;
  std::string output;  // stdout and stderr
};
Result runLogged(const std::string& command, const std::string& log) {
  Result r;
  r.rc = run(command + " > " + log + " 2>&1");
  r.output = readFile(log);
  return r;
}

std::string capture(const std::string& vcap, const std::string& options) {
  return std::string(VIPER_CAPTURE_EXE) + " --output " + vcap + " " + options + " -- ";
}
std::string testProgram(int frames) {
  return std::string(VIPER_GL_TEST_PROGRAM) + " --mode direct --size 160x120 --frames " + std::to_string(frames);
}
std::string fixedFunctionProgram(int frames) {
  return std::string(VIPER_GL_FIXED_FUNCTION_PROGRAM) + " --size 160x120 --frames " + std::to_string(frames);
}
std::string check(const std::string& vcap, const std::string& options = "") {
  return std::string(VIPER_CAPTURE_CHECK_EXE) + " " + vcap + " " + options;
}
const std::string kProfile = " --profile " VIPER_PROFILE_DIR "/viper_scene.yaml ";

std::vector<CaptureFrame> readFrames(const std::string& path) {
  std::vector<CaptureFrame> frames;
  viper::MeshRegistry meshes;
  viper::test::readCapture(path, frames, meshes);
  return frames;
}

// The verdict line `capture` printed for `vcap` ("" if none).
std::string verdictLine(const std::string& output, const std::string& vcap) {
  const std::string prefix = "capture: " + vcap + ": ";
  for (size_t at = output.find(prefix); at != std::string::npos; at = output.find(prefix, at + 1)) {
    const size_t end = output.find('\n', at);
    const std::string line = output.substr(at + prefix.size(), end - at - prefix.size());
    if (line.find("written") != std::string::npos) return line;
  }
  return "";
}

// A good capture of the test scene (6 frames at 3 frames/s of its time: it moves), made once. The
// test program's projection is orthographic, for which flow is not defined.
const std::string& sceneCapture() {
  static const std::string path = [] {
    const std::string vcap = tempDir() + "/scene.vcap";
    run(capture(vcap, "--profile " VIPER_PROFILE_DIR "/test_scene.yaml --fps 3") + VIPER_TEST_SCENE +
        " --frames 6 --width 160 --height 120 --fps 3 > /dev/null 2>&1");
    return vcap;
  }();
  return path;
}

}  // namespace

TEST(CaptureVerdict, AFixedFunctionProgramGetsIdsAndCaptureSaysWhatIsLeftOut) {
  const std::string vcap = tempDir() + "/fixed.vcap";
  const Result r = runLogged(capture(vcap, "--require-ids 0.9") + fixedFunctionProgram(3), tempDir() + "/fixed.log");
  EXPECT_EQ(r.rc, 0) << r.output;
  // Both draws are recorded without a program, from the fixed-function state, with ids from the
  // id pass: the quad's glDrawArrays (its mesh from the vertex array), the triangle's
  // glBegin/glEnd (its mesh from the vertices passed in between).
  const std::vector<CaptureFrame> frames = readFrames(vcap);
  ASSERT_EQ(frames.size(), 3u);
  Eigen::Matrix4f frustum = Eigen::Matrix4f::Zero();  // glFrustum(-0.1, 0.1, -0.075, 0.075, 0.1, 100)
  frustum(0, 0) = 1.0f, frustum(1, 1) = 1.0f / 0.75f, frustum(2, 2) = -100.1f / 99.9f;
  frustum(2, 3) = -20.0f / 99.9f, frustum(3, 2) = -1.0f;
  for (const CaptureFrame& f : frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    ASSERT_EQ(f.draws.size(), 2u);
    EXPECT_EQ(f.unrecorded_draws, 0u);
    for (const viper::DrawRecord& d : f.draws) {
      SCOPED_TRACE("draw " + std::to_string(d.index));
      EXPECT_EQ(d.program_key, viper::kFixedFunctionProgramKey);
      EXPECT_EQ(d.gaps, 0);
      EXPECT_EQ(d.matrix_flags, viper::kHasProjection);  // no profile: how the stack is split is not known
      EXPECT_TRUE(d.projection.isApprox(frustum, 1e-5f)) << d.projection;
      EXPECT_NE(d.mesh_key, 0u);
      EXPECT_GT(d.visible_pixels, 300u);
    }
    EXPECT_EQ(f.draws[1].primitive_count, 1u) << "the triangle";
    EXPECT_EQ(f.draw_ids[size_t(60) * 160 + 70], 1u);   // the quad, left
    EXPECT_EQ(f.draw_ids[size_t(60) * 160 + 100], 2u);  // the triangle, right
  }
  EXPECT_EQ(verdictLine(r.output, vcap),
            "3 frames written; ids on 100.0% of scene pixels, placed 0.0%; 6 draws recorded, 0 not; left out: 100.0% "
            "of scene pixels not placed: no --profile, so no matrices were recorded")
      << r.output;

  // With a profile that says how the program builds its matrix stack, both are placed, and their
  // ids, meshes and matrices agree (reprojection).
  const std::string profile = tempDir() + "/fixed_function.yaml";
  std::ofstream(profile) << "programs:\n  - fixed_function: true\n    matrix_stack: load_view_mult_world\n";
  const Result placed = runLogged(capture(vcap, "--profile " + profile) + fixedFunctionProgram(3), tempDir() + "/fixed_plain.log");
  EXPECT_EQ(placed.rc, 0) << placed.output;
  EXPECT_EQ(verdictLine(placed.output, vcap),
            "3 frames written; ids on 100.0% of scene pixels, placed 100.0%; 6 draws recorded, 0 not; nothing left out")
      << placed.output;
  const Result c = runLogged(check(vcap, "--flow"), tempDir() + "/fixed_check.log");
  EXPECT_EQ(c.rc, 0) << c.output;
  EXPECT_NE(c.output.find("reprojection: met: 100.00% of "), std::string::npos) << c.output;
}

TEST(CaptureVerdict, NoFrameWrittenFailsRequireIdsUnlessTheProgramFailed) {
  const std::string d = tempDir();
  // Every frame skipped: an empty stream.
  Result r = runLogged(capture(d + "/skipped.vcap", "--skip-frames 10 --require-ids 0") + testProgram(3),
                       d + "/skipped.log");
  EXPECT_EQ(r.rc, kMostlyEmpty) << r.output;
  EXPECT_EQ(verdictLine(r.output, d + "/skipped.vcap"),
            "0 frames written: no buffer swap after the 10 frames skipped (--skip-frames)")
      << r.output;
  EXPECT_EQ(readFrames(d + "/skipped.vcap").size(), 0u);
  // A program without OpenGL writes no stream; one left at the path by an earlier run is not taken for it.
  ASSERT_EQ(run(capture(d + "/none.vcap", kProfile) + testProgram(2) + " > /dev/null 2>&1"), 0);
  ASSERT_EQ(readFrames(d + "/none.vcap").size(), 2u);
  r = runLogged(capture(d + "/none.vcap", "--require-ids 0") + "true", d + "/none.log");
  EXPECT_EQ(r.rc, kMostlyEmpty) << r.output;
  EXPECT_EQ(verdictLine(r.output, d + "/none.vcap"),
            "0 frames written: the program wrote no capture stream (no frame reached a layer: not an OpenGL or "
            "Vulkan program, or it failed before its first frame)")
      << r.output;
  // The program's own failure comes first.
  EXPECT_EQ(run(capture(d + "/fails.vcap", "--require-ids 1") + "sh -c 'exit 3' 2> /dev/null"), 3);
  EXPECT_NE(run(capture(d + "/bad.vcap", "--require-ids 1.5") + "true 2> /dev/null"), 0);
  EXPECT_NE(run(capture(d + "/bad.vcap", "--require-ids most") + "true 2> /dev/null"), 0);
}

TEST(CaptureVerdict, AGoodCapturePassesAndItsChecksMeetTheirGoals) {
  const std::string vcap = tempDir() + "/good_required.vcap";
  const Result r = runLogged(capture(vcap, kProfile + "--require-ids 0.99") + testProgram(4), tempDir() + "/good.log");
  EXPECT_EQ(r.rc, 0) << r.output;
  EXPECT_EQ(verdictLine(r.output, vcap),
            "4 frames written; ids on 100.0% of scene pixels, placed 100.0%; 16 draws recorded, 0 not; nothing left out")
      << r.output;

  const Result c = runLogged(check(sceneCapture(), "--flow"), tempDir() + "/scene_check.log");
  EXPECT_EQ(c.rc, 0) << c.output;
  for (const char* line : {"reprojection: met: 100.00% of ", "reprojection depth: met: ", "flow forward-backward: met: ",
                           "flow photometric: met: ", "flow static surfaces: met: ", "boxes: not asked (--labels)",
                           "checks: 5 met their goal, 0 failed, 0 not run"})
    EXPECT_NE(c.output.find(line), std::string::npos) << line << "\n" << c.output;
  EXPECT_EQ(c.output.find("FAILED"), std::string::npos) << c.output;
}

// Without a profile nothing is placed: the verdict says why, and capture_check names the checks
// that need placed draws as not run, with that reason.
TEST(CaptureVerdict, WithoutAProfileNothingIsPlacedAndTheChecksSayWhyTheyDidNotRun) {
  const std::string vcap = tempDir() + "/unplaced.vcap";
  const Result r = runLogged(capture(vcap, "--require-ids 0.99") + testProgram(3), tempDir() + "/unplaced.log");
  EXPECT_EQ(r.rc, 0) << "ids are recorded without a profile:\n" << r.output;
  EXPECT_EQ(verdictLine(r.output, vcap),
            "3 frames written; ids on 100.0% of scene pixels, placed 0.0%; 12 draws recorded, 0 not; left out: 100.0% "
            "of scene pixels not placed: no --profile, so no matrices were recorded")
      << r.output;
  const Result c = runLogged(check(vcap, "--flow"), tempDir() + "/unplaced_check.log");
  EXPECT_EQ(c.rc, kNothingChecked) << c.output;
  EXPECT_NE(c.output.find("reprojection: not run: no draw is placed: no --profile, so no matrices were recorded"),
            std::string::npos)
      << c.output;
  EXPECT_NE(c.output.find("reprojection depth: not run: "), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("flow forward-backward: not run: "), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("flow static surfaces: not run: "), std::string::npos) << c.output;
}

// The test scene's capture with every draw's world matrix moved in every other frame (its pixels
// stay where the program drew them): the pixels lie off their reprojected triangles and the flow
// between the frames no longer matches the images. capture_check exits with a failure and says which.
TEST(CaptureVerdict, CaptureCheckFailsACaptureWhoseMatricesAreWrong) {
  const std::string moved = tempDir() + "/moved.vcap";
  {
    CaptureReader reader(sceneCapture());
    viper::CaptureWriter writer(moved, reader.header());
    CaptureFrame f;
    while (reader.next(f) == CaptureReader::Status::kFrame) {
      if (f.number % 2 == 1)
        for (viper::DrawRecord& d : f.draws) d.world.col(3).head<3>() += Eigen::Vector3f(2.0f, 1.0f, 0.0f);
      writer.write(f);
    }
  }
  const Result intact = runLogged(check(sceneCapture(), "--flow"), tempDir() + "/intact_check.log");
  ASSERT_EQ(intact.rc, 0) << intact.output;
  const Result c = runLogged(check(moved, "--flow"), tempDir() + "/moved_check.log");
  EXPECT_EQ(c.rc, kCheckFailed) << c.output;
  EXPECT_NE(c.output.find("reprojection: FAILED: "), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("flow photometric: FAILED: "), std::string::npos) << c.output;
}

// The verdict's reasons from frames made here: what the stream says, and nothing else.
TEST(CaptureVerdict, ReasonsFollowTheStream) {
  CaptureFrame f;
  f.width = 4;
  f.height = 1;
  f.depth_window = {0.5f, 0.5f, 0.5f, 1.0f};
  f.draw_ids = {1, 1, 0, 0};
  f.primitive_ids = {0, 0, 0, 0};
  f.draws.resize(1);
  f.draws[0].mesh_key = 7;
  f.draws[0].matrix_flags = viper::kHasWorld | viper::kHasView | viper::kHasProjection;
  viper::MeshRegistry meshes;
  viper::MeshRecord mesh;
  mesh.key = 7;
  mesh.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  mesh.indices = {0, 1, 2};
  meshes.add(mesh);

  viper::CaptureReadResult read;
  read.coverage.profile_given = true;
  read.coverage.add(f, meshes);  // 3 scene pixels: 2 placed, 1 with depth and no id
  EXPECT_EQ(viper::captureVerdict(read, ""),
            "1 frame written; ids on 66.7% of scene pixels, placed 66.7%; 1 draw recorded, 0 not; left out: 33.3% of "
            "scene pixels without id: depth written by draws that leave no id (mostly transparent fragments, the "
            "profile's overlay, or drawing the layer does not intercept: glBegin/glEnd, display lists)");
  f.unrecorded_draws = 2;
  f.draws[0].matrix_flags = viper::kHasView | viper::kHasProjection;  // the profile names no world
  f.draw_ids = {1, 1, 1, 0};
  read.coverage = {};
  read.coverage.profile_given = true;
  read.coverage.add(f, meshes);
  read.problem = "x.vcap: offset 99: truncated";
  EXPECT_EQ(viper::captureVerdict(read, ""),
            "1 frame written; ids on 100.0% of scene pixels, placed 0.0%; 1 draw recorded, 2 not; left out: 100.0% of "
            "scene pixels not placed: their draws lack world, view or projection: no entry of the profile names them "
            "for their programs; the stream is damaged after 1 frame: x.vcap: offset 99: truncated");
  read.coverage = {};
  read.problem.clear();
  f.draws[0].matrix_flags = viper::kHasWorld | viper::kHasView | viper::kHasProjection;
  read.coverage.add(f, meshes);
  EXPECT_EQ(viper::mainGap(read.coverage),
            "2 draws into the scene not recorded (immediate mode or display lists; without a program, no depth test "
            "or no fixed-function pipeline; or multi-draws whose shaders read gl_DrawID), leaving no pixel without id");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
