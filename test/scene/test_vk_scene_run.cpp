// Runs the real vk_test_scene binary under a private Xvfb, in every way it draws (render passes,
// dynamic rendering, offscreen with a composite and a HUD, host-visible buffers), each time under the
// Khronos validation layer (with synchronisation validation), and compares it with test_scene: the
// same oracle to the byte, nearly the same pictures. --headless runs without any display and must
// draw the windowed runs' frames to the byte.
#include "../common/process_util.h"
#include "viper/ground_truth/oracle.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace viper {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kWidth = 320, kHeight = 240;
constexpr int kFrames = 4;
const std::string kCommon = "--frames 4 --width 320 --height 240 --seed 5 --fps 10";

// The HUD panel of --offscreen in normalised device coordinates (y down), as scene/vulkan/vk_renderer.cpp
// draws it: x in [-0.95, -0.55], y in [-0.95, -0.80].
constexpr double kHudLeft = -0.95, kHudRight = -0.55, kHudTop = -0.95, kHudBottom = -0.80;

struct Mode {
  const char* name;
  const char* flags;
  bool offscreen;
};
const std::vector<Mode> kModes = {
    {"render_pass", "", false},
    {"dynamic_rendering", "--dynamic-rendering", false},
    {"host_visible", "--host-visible-buffers", false},
    {"offscreen", "--offscreen", true},
    {"offscreen_dynamic_host", "--offscreen --dynamic-rendering --host-visible-buffers", true},
    {"render_pass2", "--render-pass2 --full-push-constants", false},
    {"render_pass2_offscreen", "--render-pass2 --offscreen", true},
};

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

// An Xvfb of its own (it picks a free display and names it through -displayfd); stopped on destruction.
class PrivateXvfb {
 public:
  PrivateXvfb() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(fds[0]);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      const std::string fd = std::to_string(fds[1]);
      ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1024x768x24", "-nolisten", "tcp",
               static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    char c;
    while (pid_ > 0 && ::poll(&p, 1, 20000) > 0 && ::read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(fds[0]);
    if (!number.empty()) display_ = ":" + number;
  }
  ~PrivateXvfb() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    ::waitpid(pid_, nullptr, 0);
  }
  /// ":N", or empty if it did not start.
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

struct Image {
  std::vector<uint8_t> rgb;  // top row first
  bool valid() const { return rgb.size() == size_t{kWidth} * kHeight * 3; }
  int at(uint32_t x, uint32_t y, int c) const { return rgb[(size_t{y} * kWidth + x) * 3 + c]; }
};

Image readPpm(const fs::path& path) {
  const std::string bytes = test::readFile(path.string());
  const std::string header = "P6\n" + std::to_string(kWidth) + " " + std::to_string(kHeight) + "\n255\n";
  Image image;
  if (bytes.compare(0, header.size(), header) == 0) image.rgb.assign(bytes.begin() + header.size(), bytes.end());
  return image;
}

bool inHud(uint32_t x, uint32_t y) {
  // One pixel of margin around the panel's edges.
  const double u = (x + 0.5) / kWidth * 2 - 1, v = (y + 0.5) / kHeight * 2 - 1;
  const double mx = 2.0 / kWidth, my = 2.0 / kHeight;
  return u > kHudLeft - mx && u < kHudRight + mx && v > kHudTop - my && v < kHudBottom + my;
}

std::string frameName(int n) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.ppm", n);
  return name;
}

size_t modeIndex(const std::string& name) {
  for (size_t m = 0; m < kModes.size(); ++m)
    if (name == kModes[m].name) return m;
  ADD_FAILURE() << "no mode " << name;
  return 0;
}

// The lines of a run's log that the validation layer wrote (errors, warnings, hazards).
std::string validationReports(const std::string& log) {
  std::stringstream lines(log);
  std::string line, reported;
  while (std::getline(lines, line))
    if (line.find("Validation") != std::string::npos || line.find("VUID-") != std::string::npos ||
        line.find("SYNC-HAZARD") != std::string::npos)
      reported += line + "\n";
  return reported;
}

// The loader's own report (VK_LOADER_DEBUG=layer): the layer really was in the chain.
bool layerInserted(const std::string& log) {
  return log.find("Insert instance layer \"VK_LAYER_KHRONOS_validation\"") != std::string::npos;
}

class VkSceneRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::tempDir("viper_vk_scene_");
    if (!onPath("Xvfb")) {
      skip_ = "Xvfb is not installed (Debian: xvfb)";
      return;
    }
    xvfb_ = new PrivateXvfb();
    if (xvfb_->display().empty()) {
      skip_ = "Xvfb did not start";
      return;
    }
    const fs::path xdg = fs::path(dir_) / "xdg";
    fs::create_directories(xdg);
    ::chmod(xdg.c_str(), 0700);
    // Errors and warnings of the core checks and of synchronisation validation, logged to stdout.
    std::ofstream(fs::path(dir_) / "vk_layer_settings.txt")
        << "khronos_validation.report_flags = error,warn\n"
           "khronos_validation.debug_action = VK_DBG_LAYER_ACTION_LOG_MSG\n"
           "khronos_validation.enables = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT\n";
    env_ = "env DISPLAY=" + xvfb_->display() + " XDG_RUNTIME_DIR=" + xdg.string() + " ";
    const std::string validation =
        "VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation VK_LAYER_SETTINGS_PATH=" + dir_ + " VK_LOADER_DEBUG=layer ";
    validated_env_ = env_ + validation;
    headless_env_ = "env -u DISPLAY XDG_RUNTIME_DIR=" + xdg.string() + " " + validation;

    const std::string probe_log = dir_ + "/probe.log";
    if (test::run(env_ + VIPER_VK_TEST_SCENE_BIN " --frames 1 --width 64 --height 48 >" + probe_log + " 2>&1") != 0 &&
        test::readFile(probe_log).find("no Vulkan device") != std::string::npos) {
      skip_ = "no Vulkan device: " + test::readFile(probe_log);
      return;
    }
    gl_status_ = test::run(std::string(VIPER_TEST_SCENE_BIN " ") + kCommon + " --oracle " + dir_ + "/gl.oracle" +
                           " --dump-dir " + dir_ + "/gl >/dev/null 2>&1");
    for (const Mode& mode : kModes) {
      const std::string base = dir_ + "/" + mode.name;
      status_.push_back(test::run(validated_env_ + VIPER_VK_TEST_SCENE_BIN " " + kCommon + " " + mode.flags +
                                  " --oracle " + base + ".oracle --dump-dir " + base + " >" + base + ".log 2>&1"));
    }
  }
  static void TearDownTestSuite() {
    delete xvfb_;
    xvfb_ = nullptr;
    fs::remove_all(dir_);
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
  }

  static std::string dir_, env_, validated_env_, headless_env_, skip_;
  static PrivateXvfb* xvfb_;
  static int gl_status_;
  static std::vector<int> status_;  // by kModes
};
std::string VkSceneRun::dir_, VkSceneRun::env_, VkSceneRun::validated_env_, VkSceneRun::headless_env_,
    VkSceneRun::skip_;
PrivateXvfb* VkSceneRun::xvfb_ = nullptr;
int VkSceneRun::gl_status_ = -1;
std::vector<int> VkSceneRun::status_;

TEST_F(VkSceneRun, EveryModeRunsCleanUnderTheValidationLayer) {
  for (size_t m = 0; m < kModes.size(); ++m) {
    SCOPED_TRACE(kModes[m].name);
    const std::string log = test::readFile(dir_ + "/" + kModes[m].name + ".log");
    EXPECT_EQ(status_[m], 0) << log;
    EXPECT_TRUE(layerInserted(log)) << log;
    EXPECT_EQ(validationReports(log), "");
  }
}

TEST_F(VkSceneRun, HeadlessDrawsTheWindowedFramesWithoutADisplay) {
  // No DISPLAY at all: a run that opened X would fail. The scene is the same, only the image it is
  // drawn into differs (its own R8G8B8A8 rather than the swapchain's), so the dumped frames and the
  // oracle are the windowed run's to the byte, in each way of drawing.
  for (const char* name : {"render_pass", "dynamic_rendering", "render_pass2", "offscreen"}) {
    SCOPED_TRACE(name);
    const size_t m = modeIndex(name);
    ASSERT_EQ(status_[m], 0);
    const std::string base = dir_ + "/headless_" + name;
    const int status = test::run(headless_env_ + VIPER_VK_TEST_SCENE_BIN " " + kCommon + " " + kModes[m].flags +
                                 " --headless --oracle " + base + ".oracle --dump-dir " + base + " >" + base +
                                 ".log 2>&1");
    const std::string log = test::readFile(base + ".log");
    ASSERT_EQ(status, 0) << log;
    EXPECT_NE(log.find("headless"), std::string::npos) << log;
    EXPECT_TRUE(layerInserted(log)) << log;
    EXPECT_EQ(validationReports(log), "");
    const std::string oracle = test::readFile(base + ".oracle");
    EXPECT_FALSE(oracle.empty());
    EXPECT_TRUE(oracle == test::readFile(dir_ + "/" + name + ".oracle")) << "the oracles differ";
    for (int n = 0; n < kFrames; ++n) {
      SCOPED_TRACE("frame " + std::to_string(n));
      const std::string headless = test::readFile((fs::path(base) / frameName(n)).string());
      ASSERT_TRUE(readPpm(fs::path(base) / frameName(n)).valid());
      // Not EXPECT_EQ: a failure would print two 230 KB strings.
      EXPECT_TRUE(headless == test::readFile((fs::path(dir_) / name / frameName(n)).string())) << "the frames differ";
    }
  }
}

TEST_F(VkSceneRun, OracleEqualsTestScenes) {
  ASSERT_EQ(gl_status_, 0);
  const std::string expected = test::readFile(dir_ + "/gl.oracle");
  const Oracle oracle = readOracle(dir_ + "/gl.oracle");
  ASSERT_EQ(oracle.frames.size(), static_cast<size_t>(kFrames));
  ASSERT_FALSE(oracle.frames[0].draws.empty());
  ASSERT_FALSE(oracle.meshes.empty());
  for (size_t m = 0; m < kModes.size(); ++m) {
    SCOPED_TRACE(kModes[m].name);
    ASSERT_EQ(status_[m], 0);
    // Same draws in the same order, same matrices (OpenGL conventions), same meshes: the same bytes.
    EXPECT_EQ(test::readFile(dir_ + "/" + kModes[m].name + ".oracle"), expected);
  }
}

TEST_F(VkSceneRun, FramesAgreeWithTestScene) {
  ASSERT_EQ(gl_status_, 0);
  for (size_t m = 0; m < kModes.size(); ++m) {
    SCOPED_TRACE(kModes[m].name);
    ASSERT_EQ(status_[m], 0);
    for (int n = 0; n < kFrames; ++n) {
      SCOPED_TRACE("frame " + std::to_string(n));
      const Image gl = readPpm(fs::path(dir_) / "gl" / frameName(n));
      const Image vk = readPpm(fs::path(dir_) / kModes[m].name / frameName(n));
      ASSERT_TRUE(gl.valid());
      ASSERT_TRUE(vk.valid());
      // Rasterisers may differ at triangle edges: count pixels more than 4 levels apart.
      size_t compared = 0, differing = 0;
      double hud_gl = 0, hud_vk = 0;
      for (uint32_t y = 0; y < kHeight; ++y)
        for (uint32_t x = 0; x < kWidth; ++x) {
          int d = 0;
          for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(gl.at(x, y, c) - vk.at(x, y, c)));
          if (kModes[m].offscreen && inHud(x, y)) {
            for (int c = 0; c < 3; ++c) {
              hud_gl += gl.at(x, y, c);
              hud_vk += vk.at(x, y, c);
            }
            continue;
          }
          ++compared;
          differing += d > 4;
        }
      const double share = static_cast<double>(differing) / compared;
      RecordProperty(std::string(kModes[m].name) + "_frame" + std::to_string(n) + "_share_over_4_levels",
                     std::to_string(share));
      EXPECT_LT(share, 0.005) << differing << " of " << compared << " pixels differ by more than 4 levels";
      // The HUD panel (dark, three quarters opaque) darkens its corner of the picture.
      if (kModes[m].offscreen) {
        EXPECT_LT(hud_vk, 0.5 * hud_gl) << "no HUD panel in the top-left corner";
      }
    }
  }
}

TEST_F(VkSceneRun, ModesDrawTheSamePixels) {
  // One device, one set of pipelines: how the frame is submitted changes nothing in the picture,
  // and the offscreen composite copies the scene pixel for pixel (outside the HUD).
  for (size_t m = 1; m < kModes.size(); ++m) {
    SCOPED_TRACE(kModes[m].name);
    ASSERT_EQ(status_[0], 0);
    ASSERT_EQ(status_[m], 0);
    for (int n = 0; n < kFrames; ++n) {
      const Image a = readPpm(fs::path(dir_) / kModes[0].name / frameName(n));
      const Image b = readPpm(fs::path(dir_) / kModes[m].name / frameName(n));
      ASSERT_TRUE(a.valid() && b.valid());
      size_t differing = 0;
      for (uint32_t y = 0; y < kHeight; ++y)
        for (uint32_t x = 0; x < kWidth; ++x) {
          if (kModes[m].offscreen && inHud(x, y)) continue;
          for (int c = 0; c < 3; ++c) differing += a.at(x, y, c) != b.at(x, y, c);
        }
      EXPECT_EQ(differing, 0u) << "frame " << n;
    }
  }
}

// Needs neither X nor Vulkan: these fail before either is opened.
TEST(VkSceneOptions, ClearErrorsAndExitCodes) {
  const std::string bin = VIPER_VK_TEST_SCENE_BIN;
  const std::string log = (fs::temp_directory_path() / ("viper_vk_errors_" + std::to_string(::getpid()) + ".log")).string();
  EXPECT_EQ(test::run("env -u DISPLAY " + bin + " --frames 1 >" + log + " 2>&1"), 1);
  EXPECT_NE(test::readFile(log).find("DISPLAY is not set"), std::string::npos) << test::readFile(log);
  fs::remove(log);
  EXPECT_EQ(test::run(bin + " --gl-loader direct >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --offscreen=yes >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --headless=yes >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --frames 0 >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --no-such-option >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --help >/dev/null 2>&1"), 0);
}

// --frame-ms holds every frame to at least that long, as a program held to a frame rate is (what
// the capture-overhead measurement at 60 frames/s relies on); --benchmark counts the sleep.
TEST(VkSceneOptions, FrameMsHoldsEveryFrame) {
  const std::string bin = VIPER_VK_TEST_SCENE_BIN;
  // The binary's one temporary folder (test::tempDir), which the fixture above removes when done.
  const fs::path dir = fs::path(test::tempDir("viper_vk_scene_")) / "frame_ms";
  fs::create_directories(dir);
  const fs::path log = dir / "run.log";
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(test::run(bin + " --headless --frames 5 --width 64 --height 64 --benchmark --frame-ms 60 >" + log.string() +
                      " 2>&1"),
            0)
      << test::readFile(log.string());
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(wall_ms, 5 * 60.0);
  const std::string out = test::readFile(log.string());
  const size_t at = out.find("mean_frame_ms=");
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_GE(std::stod(out.substr(at + 14)), 60.0) << out;
  EXPECT_EQ(test::run(bin + " --headless --frame-ms 0 >/dev/null 2>&1"), 2);
  EXPECT_EQ(test::run(bin + " --headless --frame-ms=x >/dev/null 2>&1"), 2);
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
