// Direct3D 11 through wine: d3d11_scene.exe (test/d3d11/, built with mingw-w64) runs under wine,
// whose wined3d turns its Direct3D 11 calls into OpenGL, and `capture` records it with the OpenGL
// layer and config/profiles/d3d11_scene.yaml. The capture is compared with the program's own truth
// (its oracle file; docs/capture_layer.md, "Direct3D 11 through wine"):
//  - every draw, in order, with ids on every scene pixel, and depth;
//  - ids and depth the same way up as the colour, though wined3d draws into a texture of its own
//    with y negated (its `pos_fixup`) and blits it flipped into the window at Present (regression:
//    they were upside down);
//  - each draw's mesh, equal to the program's, though wined3d makes its buffer objects on
//    GL_PIXEL_UNPACK_BUFFER and draws from them as vertex and index buffers (regression: none);
//  - world, view and projection read from the registers of wined3d's `vs_cb0` array as rows, the
//    projection in OpenGL's clip depth (`clip_depth: zero_to_one`): equal to the program's, and every
//    id pixel placed on its triangle at its depth with them.
// Each run gets its own Xvfb (xvfb-run) and a fresh wine prefix.
#include "../common/process_util.h"
#include "capture_checks.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/ground_truth/oracle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <string>
#include <vector>

namespace viper {
namespace {

using test::readFile;
using test::run;

constexpr int kFrames = 5;
constexpr uint32_t kWidth = 320, kHeight = 240;

std::string dir() { return test::tempDir("viper_d3d11_capture_"); }

bool haveWineAndXvfb(std::string& missing) {
  if (run("command -v wine > /dev/null") != 0) missing = "wine (apt-get install wine wine64)";
  else if (run("command -v xvfb-run > /dev/null") != 0) missing = "xvfb-run (apt-get install xvfb)";
  return missing.empty();
}

// `command` under wine with a fresh prefix and a private X server, its output to `log`. The wine
// server is stopped at the end (it would otherwise outlive the X server by a few seconds).
int underWine(const std::string& command, const std::string& log) {
  const std::string env = "XDG_RUNTIME_DIR=" + dir() + " WINEPREFIX=" + dir() + "/prefix WINEDEBUG=-all" +
                          " WINEDLLOVERRIDES='mscoree,mshtml='";
  return run(env + " xvfb-run -a -s '-screen 0 640x480x24' sh -c '" + command +
             "; status=$?; wineserver -k; exit $status' > " + log + " 2>&1");
}

// The frame's draws placed with the program's own matrices and mesh instead of the captured ones.
CaptureFrame placedWithTruth(CaptureFrame frame, const OracleFrame& truth, uint64_t mesh_key) {
  for (size_t i = 0; i < frame.draws.size() && i < truth.draws.size(); ++i) {
    DrawRecord& d = frame.draws[i];
    d.world = truth.draws[i].world;
    d.view = truth.view;
    d.projection = truth.projection;
    d.matrix_flags = kHasWorld | kHasView | kHasProjection;
    d.mesh_key = mesh_key;
  }
  return frame;
}

// Largest difference of two matrices relative to the largest entry of `b` (at least 1).
float matrixError(const GlMatrix& a, const GlMatrix& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0f, b.cwiseAbs().maxCoeff());
}

// The clear colour of d3d11_scene (0.55, 0.7, 0.9) in 8 bits, within rounding.
bool isClearColour(const uint8_t* rgb) {
  return std::abs(rgb[0] - 140) <= 2 && std::abs(rgb[1] - 179) <= 2 && std::abs(rgb[2] - 230) <= 2;
}

double withinHalfPixel(const ReprojectionCheck& c) {
  return std::count_if(c.distance_px.begin(), c.distance_px.end(), [](float v) { return v <= 0.5f; }) /
         static_cast<double>(std::max<size_t>(c.distance_px.size(), 1));
}

TEST(D3d11Capture, EveryDrawWithIdsDepthMeshAndMatricesAgainstTheProgramsTruth) {
  std::string missing;
  if (!haveWineAndXvfb(missing)) GTEST_SKIP() << missing << " not installed";
  const std::string vcap = dir() + "/d3d11.vcap", oracle_path = dir() + "/d3d11.oracle", log = dir() + "/d3d11.log";
  ASSERT_EQ(underWine(std::string(VIPER_CAPTURE_BIN) + " --output " + vcap + " --profile " + VIPER_SOURCE_DIR +
                          "/config/profiles/d3d11_scene.yaml -- wine " + VIPER_D3D11_SCENE_EXE + " --frames " +
                          std::to_string(kFrames) + " --width " + std::to_string(kWidth) + " --height " +
                          std::to_string(kHeight) + " --oracle " + oracle_path,
                      log),
            0)
      << readFile(log);
  EXPECT_NE(readFile(log).find("d3d11_scene: 5 frames presented"), std::string::npos) << readFile(log);
  EXPECT_NE(readFile(log).find("5 frames written"), std::string::npos) << readFile(log);
  // Every name the profile gives is found in wined3d's program.
  EXPECT_EQ(readFile(log).find("which it does not use"), std::string::npos) << readFile(log);

  std::vector<CaptureFrame> frames;
  MeshRegistry captured_meshes;
  test::readCapture(vcap, frames, captured_meshes);
  const Oracle oracle = readOracle(oracle_path);
  ASSERT_EQ(frames.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(oracle.frames.size(), static_cast<size_t>(kFrames));
  const OracleMesh* cube = oracle.mesh("cube");
  ASSERT_NE(cube, nullptr);
  MeshRecord truth_mesh;
  truth_mesh.key = 0xd3d11;
  truth_mesh.positions_xyz = cube->positions_xyz;
  truth_mesh.indices = cube->indices;
  MeshRegistry truth_meshes;
  truth_meshes.add(truth_mesh);

  ReprojectionCheck captured, with_truth;
  uint64_t pixels = 0, colour_agrees = 0;
  float worst_world = 0, worst_view = 0, worst_projection = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const CaptureFrame& frame = frames[f];
    const OracleFrame& truth = oracle.frames[f];
    EXPECT_EQ(frame.width, kWidth);
    EXPECT_EQ(frame.height, kHeight);
    // Every draw the program made, in its order, each owning pixels, with its mesh and matrices.
    ASSERT_EQ(frame.draws.size(), truth.draws.size());
    EXPECT_EQ(frame.unrecorded_draws, 0u);
    for (const DrawRecord& d : frame.draws) {
      SCOPED_TRACE("draw " + std::to_string(d.index) + " (" + truth.draws[d.index].part + ")");
      EXPECT_GT(d.visible_pixels, 0u);
      EXPECT_EQ(d.primitive_count, 12u);
      EXPECT_EQ(d.gaps, 0);
      EXPECT_EQ(d.matrix_flags, kHasWorld | kHasView | kHasProjection);
      const MeshRecord* mesh = captured_meshes.find(d.mesh_key);
      ASSERT_NE(mesh, nullptr);
      // The program's vertices and indices, mirrored in z as the truth is (handedness: left).
      EXPECT_TRUE(truth_meshes.holds(truth_mesh.key, mesh->positions_xyz, mesh->indices));
      worst_world = std::max(worst_world, matrixError(d.world, truth.draws[d.index].world));
      worst_view = std::max(worst_view, matrixError(d.view, truth.view));
      worst_projection = std::max(worst_projection, matrixError(d.projection, truth.projection));
    }
    // Right side up: the pixels without an id are exactly those of the clear colour.
    for (size_t i = 0; i < frame.draw_ids.size(); ++i)
      colour_agrees += (frame.draw_ids[i] == 0) == isClearColour(&frame.color_rgb[3 * i]);
    pixels += frame.draw_ids.size();
    captured.add(checkReprojection(frame, captured_meshes));
    with_truth.add(checkReprojection(placedWithTruth(frame, truth, truth_mesh.key), truth_meshes));
  }
  std::printf("d3d11 through wine: ids on %.2f%% of scene pixels, placed %.2f%%; captured: %.3f%% within 0.5 px, "
              "depth p99 %.2e relative; with the program's truth: %.3f%% within 0.5 px, depth p99 %.2e; id/colour "
              "agreement %.4f%%; matrices vs truth: world %.1e, view %.1e, projection %.1e\n",
              100.0 * captured.id_pixels / std::max<uint64_t>(captured.scene_pixels, 1),
              100.0 * captured.placed_pixels / std::max<uint64_t>(captured.id_pixels, 1), 100.0 * withinHalfPixel(captured),
              quantile(captured.depth_relative, 0.99), 100.0 * withinHalfPixel(with_truth),
              quantile(with_truth.depth_relative, 0.99), 100.0 * colour_agrees / std::max<uint64_t>(pixels, 1),
              worst_world, worst_view, worst_projection);
  EXPECT_LE(worst_world, 1e-5f);
  EXPECT_LE(worst_view, 1e-5f);
  EXPECT_LE(worst_projection, 1e-5f);
  EXPECT_EQ(captured.id_pixels, captured.scene_pixels);
  EXPECT_EQ(captured.placed_pixels, captured.id_pixels);
  EXPECT_EQ(captured.checked_pixels, captured.id_pixels);
  EXPECT_GE(static_cast<double>(colour_agrees) / pixels, 0.999);
  // Every id pixel lies on the triangle its draw and primitive name, at its depth, placed with the
  // captured matrices and mesh, and with the program's own.
  EXPECT_GE(withinHalfPixel(captured), 0.995);
  EXPECT_LE(quantile(captured.depth_relative, 0.99), 1e-3);
  EXPECT_GE(withinHalfPixel(with_truth), 0.995);
  EXPECT_LE(quantile(with_truth.depth_relative, 0.99), 1e-3);
}

}  // namespace
}  // namespace viper
