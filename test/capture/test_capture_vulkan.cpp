// The Vulkan capture layer on our Vulkan oracle program (vk_test_scene) in every way it draws:
// render passes, dynamic rendering, an offscreen scene composited under a HUD, staged and
// host-visible buffers, the staged ones also read through the layer's shadows of their copies as
// on a discrete GPU. Each capture is compared with the program's own truth (its oracle: draws,
// matrices, meshes) exactly, its ids and depth against the reprojected meshes, its pictures with
// the program's own, frame by frame, with and without the layer; and the layer adds no error of
// the Khronos validation layer. Each run gets its own Xvfb (xvfb-run).
#include "../common/process_util.h"
#include "capture_checks.h"
#include "src/capture/vulkan/vk_state.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/ground_truth/oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace viper {
namespace {

namespace fs = std::filesystem;
using test::readFile;
using test::run;

const std::string kCommon = "--frames 4 --width 320 --height 240 --seed 3 --fps 10";

std::string dir() { return test::tempDir("viper_vk_capture_"); }

bool haveXvfbAndVulkan() {
  return run("command -v xvfb-run > /dev/null") == 0 && run("command -v vulkaninfo > /dev/null") == 0;
}

// Runs `command` with a private X server; its output to `log`.
int underXvfb(const std::string& command, const std::string& log) {
  return run("XDG_RUNTIME_DIR=" + dir() + " xvfb-run -a -s '-screen 0 640x480x24' " + command + " > " + log + " 2>&1");
}

std::string capture(const std::string& out, const std::string& flags, const std::string& extra_env = "") {
  return extra_env + " " + VIPER_CAPTURE_BIN + " --output " + out + " --profile " + VIPER_SOURCE_DIR +
         "/config/profiles/vk_test_scene.yaml --fps 10 -- " + VIPER_VK_TEST_SCENE_BIN + " " + kCommon + " " + flags;
}

bool sameMatrix(const GlMatrix& a, const GlMatrix& b, float tolerance) {
  return (a - b).cwiseAbs().maxCoeff() <= tolerance * std::max(1.0f, b.cwiseAbs().maxCoeff());
}

// The layer's copy-following path (a discrete GPU's device-local buffers, filled by staging
// copies) on a driver whose memory is all host-visible: copy destinations are read from the
// layer's shadows only.
const char* const kShadowCopies = "VIPER_VULKAN_SHADOW_COPIES=1";

struct Mode {
  const char* name;
  const char* flags;
  const char* env = "";  ///< variables set for the capture
};

class VulkanCapture : public ::testing::TestWithParam<Mode> {};

TEST_P(VulkanCapture, EqualsTheProgramsOwnTruth) {
  if (!haveXvfbAndVulkan()) GTEST_SKIP() << "xvfb-run or vulkaninfo (vulkan-tools) not installed";
  const Mode& mode = GetParam();
  const std::string base = dir() + "/" + mode.name;
  const std::string vcap = base + ".vcap", oracle_path = base + ".oracle", log = base + ".log";
  ASSERT_EQ(underXvfb(capture(vcap, std::string(mode.flags) + " --oracle " + oracle_path + " --dump-dir " + base + "_with",
                              std::string("env ") + mode.env),
                      log),
            0)
      << readFile(log);
  EXPECT_NE(readFile(log).find("4 frames written"), std::string::npos) << readFile(log);
  EXPECT_NE(readFile(log).find("nothing left out"), std::string::npos) << readFile(log);

  std::vector<CaptureFrame> frames;
  MeshRegistry meshes;
  test::readCapture(vcap, frames, meshes);
  const Oracle oracle = readOracle(oracle_path);
  ASSERT_EQ(frames.size(), 4u);
  ASSERT_EQ(oracle.frames.size(), 4u);
  ReprojectionCheck reprojection;
  for (size_t f = 0; f < frames.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const CaptureFrame& frame = frames[f];
    const OracleFrame& truth = oracle.frames[f];
    EXPECT_EQ(frame.width, 320u);
    EXPECT_EQ(frame.height, 240u);
    EXPECT_DOUBLE_EQ(frame.time_s, truth.time_s);
    // Every draw of the scene, in order, with the matrices the program used and its mesh.
    ASSERT_EQ(frame.draws.size(), truth.draws.size());
    EXPECT_EQ(frame.unrecorded_draws, 0u);
    for (size_t i = 0; i < frame.draws.size(); ++i) {
      SCOPED_TRACE("draw " + std::to_string(i) + " (" + truth.draws[i].part + ")");
      const DrawRecord& d = frame.draws[i];
      EXPECT_EQ(d.gaps, 0);
      ASSERT_EQ(d.matrix_flags, kHasWorld | kHasView | kHasProjection);
      EXPECT_EQ(d.world, truth.draws[i].world);  // push constants: the bytes the program pushed
      EXPECT_EQ(d.view, truth.view);            // a uniform buffer at a dynamic offset
      // The program's projection is GL's in Vulkan's clip space (y down, depth 0..1): the capture
      // records GL's again, to float rounding.
      EXPECT_TRUE(sameMatrix(d.projection, truth.projection, 1e-6f)) << d.projection << "\n\n" << truth.projection;
      const OracleMesh* mesh = oracle.mesh(truth.draws[i].mesh);
      const MeshRecord* captured = meshes.find(d.mesh_key);
      ASSERT_TRUE(mesh && captured);
      EXPECT_EQ(captured->positions_xyz, mesh->positions_xyz);
      EXPECT_EQ(captured->indices, mesh->indices);
    }
    reprojection.add(checkReprojection(frame, meshes));
  }
  // Ids and depth against the triangles they name. The skinned person is placed rigidly (the
  // Vulkan layer does not record deformed positions yet): its pixels are the ones off by more.
  const double within = std::count_if(reprojection.distance_px.begin(), reprojection.distance_px.end(),
                                      [](float v) { return v <= 0.5f; }) /
                        static_cast<double>(reprojection.distance_px.size());
  std::printf("%s: ids on %.2f%% of scene pixels, %.3f%% within 0.5 px, depth p99 %.2e relative\n", mode.name,
              100.0 * reprojection.id_pixels / reprojection.scene_pixels, 100.0 * within,
              quantile(reprojection.depth_relative, 0.99));
  EXPECT_EQ(reprojection.id_pixels, reprojection.scene_pixels);
  EXPECT_EQ(reprojection.placed_pixels, reprojection.id_pixels);
  EXPECT_GE(within, 0.995);
  EXPECT_LE(quantile(reprojection.depth_relative, 0.99), 1e-3);

  // The program does not notice: its frames are the same without the layer, and the capture's
  // colour is what it showed.
  const std::string without = base + "_without";
  ASSERT_EQ(underXvfb(std::string(VIPER_VK_TEST_SCENE_BIN) + " " + kCommon + " " + mode.flags + " --dump-dir " + without,
                      log),
            0)
      << readFile(log);
  for (int f = 0; f < 4; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%06d.ppm", f);
    const std::string with_capture = readFile(base + "_with" + name);
    ASSERT_FALSE(with_capture.empty()) << name;
    EXPECT_TRUE(with_capture == readFile(without + name)) << name << " differs with the layer";
    // PPM: "P6\n320 240\n255\n" then RGB rows, top first, as the capture's colour.
    const size_t header = with_capture.size() - 320 * 240 * 3;
    const std::vector<uint8_t>& color = frames[static_cast<size_t>(f)].color_rgb;
    ASSERT_EQ(color.size(), 320u * 240 * 3);
    size_t differing = 0, first = color.size();
    for (size_t i = 0; i < color.size(); ++i)
      if (color[i] != static_cast<uint8_t>(with_capture[header + i])) ++differing, first = std::min(first, i);
    EXPECT_EQ(differing, 0u) << name << ": the capture's colour is not what the program presented (first at byte "
                             << first << ": " << int(color[first]) << " vs " << int(static_cast<uint8_t>(with_capture[header + first]))
                             << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, VulkanCapture,
                         ::testing::Values(Mode{"render_pass", ""}, Mode{"dynamic_rendering", "--dynamic-rendering"},
                                           Mode{"host_visible", "--host-visible-buffers"},
                                           Mode{"offscreen", "--offscreen --dynamic-rendering"},
                                           // No room in the push constants (as in SuperTuxKart): the
                                           // ids come from a uniform buffer of the layer's.
                                           Mode{"push_constants_full", "--full-push-constants"},
                                           Mode{"push_constants_full_dynamic", "--full-push-constants --dynamic-rendering"},
                                           // Vulkan 1.2/1.3's structures: vkCreateRenderPass2,
                                           // imageless framebuffers, vkQueueSubmit2.
                                           Mode{"render_pass2", "--render-pass2"},
                                           Mode{"render_pass2_offscreen", "--render-pass2 --offscreen"},
                                           // No swapchain: a frame ends with each submission of the
                                           // scene pass, its colour the pass's own.
                                           Mode{"headless", "--headless"},
                                           Mode{"headless_dynamic_rendering", "--headless --dynamic-rendering"},
                                           Mode{"headless_render_pass2", "--headless --render-pass2"},
                                           // Staged device-local buffers read from the layer's
                                           // shadows of what was copied into them.
                                           Mode{"staged_shadowed", "", kShadowCopies},
                                           Mode{"headless_shadowed", "--headless", kShadowCopies}),
                         [](const ::testing::TestParamInfo<Mode>& info) { return std::string(info.param.name); });

// The Khronos validation layer, below ours, sees every call the program and the layer make: the
// layer must add no error to a program that has none.
TEST(VulkanCaptureValidation, AddsNoValidationError) {
  if (!haveXvfbAndVulkan()) GTEST_SKIP() << "xvfb-run or vulkaninfo (vulkan-tools) not installed";
  if (!fs::exists("/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json"))
    GTEST_SKIP() << "vulkan-validationlayers not installed";
  for (const Mode& mode : {Mode{"", ""}, Mode{"", "--dynamic-rendering --offscreen"}, Mode{"", "--full-push-constants"},
                           Mode{"", "--render-pass2 --offscreen"}, Mode{"", "--headless"}, Mode{"", "", kShadowCopies}}) {
    SCOPED_TRACE(std::string(mode.flags) + " " + mode.env);
    const std::string log = dir() + "/validation.log";
    ASSERT_EQ(underXvfb(capture(dir() + "/validation.vcap", mode.flags,
                                std::string("env VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation ") + mode.env),
                        log),
              0)
        << readFile(log);
    const std::string text = readFile(log);
    EXPECT_NE(text.find("4 frames written"), std::string::npos) << text;
    EXPECT_EQ(text.find("Validation Error"), std::string::npos) << text;
    EXPECT_EQ(text.find("VUID"), std::string::npos) << text;
  }
}

// The shadow of a buffer the layer cannot read (vk_state.h) knows which of its bytes were written:
// only ranges wholly written are read, and a copy from an unknown range makes its destination
// unknown again.
TEST(VulkanBufferShadow, KnowsWhichBytesWereWritten) {
  using Runs = std::vector<std::pair<VkDeviceSize, VkDeviceSize>>;
  capture::vulkan::BufferShadow s;
  s.size = 100;
  EXPECT_FALSE(s.covers(0, 1));
  EXPECT_TRUE(s.covers(5, 5));  // nothing to read
  s.mark(10, 20, true);
  s.mark(30, 40, true);
  EXPECT_TRUE(s.covers(10, 20));
  EXPECT_FALSE(s.covers(10, 21));
  EXPECT_FALSE(s.covers(15, 35));
  EXPECT_EQ(s.validFrom(12), 8u);
  EXPECT_EQ(s.validFrom(20), 0u);
  EXPECT_EQ(s.validFrom(5), 0u);
  // Touching and overlapping ranges merge.
  s.mark(20, 30, true);
  EXPECT_EQ(s.valid.size(), 1u);
  EXPECT_TRUE(s.covers(10, 40));
  EXPECT_EQ(s.validFrom(10), 30u);
  s.mark(35, 60, true);
  EXPECT_EQ(s.validRuns(0, 100), (Runs{{10, 60}}));
  // An unknown range in the middle splits it; runs are clipped to what is asked.
  s.mark(25, 45, false);
  EXPECT_EQ(s.validRuns(0, 100), (Runs{{10, 25}, {45, 60}}));
  EXPECT_EQ(s.validRuns(20, 50), (Runs{{20, 25}, {45, 50}}));
  EXPECT_FALSE(s.covers(20, 50));
  EXPECT_EQ(s.validFrom(45), 15u);
  // Unknown over the ends of ranges and over all of them.
  s.mark(0, 12, false);
  s.mark(58, 100, false);
  EXPECT_EQ(s.validRuns(0, 100), (Runs{{12, 25}, {45, 58}}));
  s.mark(0, 100, false);
  EXPECT_TRUE(s.valid.empty());
  s.mark(0, 100, true);
  EXPECT_TRUE(s.covers(0, 100));
}

// `capture` says when a program wrote nothing, and a Vulkan program run without an output is left
// alone (the layer loaded, nothing written, the frames the same).
TEST(VulkanCaptureValidation, WithoutAnOutputTheLayerOnlyPassesCallsOn) {
  if (!haveXvfbAndVulkan()) GTEST_SKIP() << "xvfb-run or vulkaninfo (vulkan-tools) not installed";
  const std::string log = dir() + "/passthrough.log";
  ASSERT_EQ(underXvfb("env VK_ADD_LAYER_PATH=" + std::string(VIPER_VULKAN_LAYER_DIR) +
                          " VK_INSTANCE_LAYERS=VK_LAYER_VIPER_capture VK_LOADER_DEBUG=layer " + VIPER_VK_TEST_SCENE_BIN +
                          " " + kCommon + " --dump-dir " + dir() + "/pass",
                      log),
            0)
      << readFile(log);
  EXPECT_NE(readFile(log).find("VK_LAYER_VIPER_capture"), std::string::npos) << "the layer was not loaded";
  EXPECT_EQ(readFile(log).find("[viper capture]"), std::string::npos) << readFile(log);
}

#ifdef VIPER_VULKAN_LAYER_ASAN_DIR
// The layer built with AddressSanitizer and UndefinedBehaviorSanitizer (viper_vulkan_layer_asan),
// in the ways the oracle program draws that take different paths through it: nothing reported, the
// capture whole. `capture --library` the sanitized GL layer preloads the sanitizer's runtime first.
TEST(VulkanCaptureSanitized, AddressAndUndefinedBehaviorSanitizersFindNothing) {
  if (!haveXvfbAndVulkan()) GTEST_SKIP() << "xvfb-run or vulkaninfo (vulkan-tools) not installed";
  for (const Mode& mode : {Mode{"", ""}, Mode{"", "--dynamic-rendering --offscreen --full-push-constants"},
                           Mode{"", "--render-pass2 --host-visible-buffers"}, Mode{"", "--headless --dynamic-rendering"},
                           Mode{"", "--headless", kShadowCopies}}) {
    SCOPED_TRACE(std::string(mode.flags) + " " + mode.env);
    const std::string log = dir() + "/asan.log";
    const std::string command =
        std::string("env ASAN_OPTIONS=detect_leaks=0:halt_on_error=1:abort_on_error=0 ") +
        "UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 VIPER_VULKAN_LAYER_PATH=" VIPER_VULKAN_LAYER_ASAN_DIR " " +
        mode.env + " " + VIPER_CAPTURE_BIN + " --library " VIPER_INTERCEPT_ASAN_LIB " --output " + dir() + "/asan.vcap --profile " +
        VIPER_SOURCE_DIR + "/config/profiles/vk_test_scene.yaml --fps 10 -- " + VIPER_VK_TEST_SCENE_BIN + " " + kCommon +
        " " + mode.flags;
    ASSERT_EQ(underXvfb(command, log), 0) << readFile(log);
    const std::string text = readFile(log);
    EXPECT_NE(text.find("4 frames written"), std::string::npos) << text;
    EXPECT_NE(text.find("nothing left out"), std::string::npos) << text;
    EXPECT_EQ(text.find("AddressSanitizer"), std::string::npos) << text;
    EXPECT_EQ(text.find("runtime error"), std::string::npos) << text;
  }
}
#endif

}  // namespace
}  // namespace viper
