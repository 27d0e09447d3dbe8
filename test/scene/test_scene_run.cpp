// Runs the real test_scene binary and checks what its oracle promises (the scene's structure and
// conventions) and what its pictures show: determinism, both GL loaders, and the documented camera
// convention against the core's ego-motion code.
#include "viper/ground_truth/ego_motion.h"
#include "viper/ground_truth/oracle.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>

namespace viper {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kWidth = 160, kHeight = 120;
constexpr int kFrames = 6;

// Runs test_scene with `args`; returns its exit status (-1 if it did not exit normally).
int runScene(const std::string& args) {
  const std::string command = std::string(VIPER_TEST_SCENE_BIN) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class SceneRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::path(::testing::TempDir()) / ("viper_scene_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string common =
        "--frames " + std::to_string(kFrames) + " --width " + std::to_string(kWidth) + " --height " +
        std::to_string(kHeight) + " --seed 3 ";
    status_direct_ = runScene(common + "--oracle " + (dir_ / "direct.oracle").string() + " --dump-dir " +
                              (dir_ / "direct").string());
    status_again_ = runScene(common + "--dump-dir " + (dir_ / "again").string());
    status_proc_ = runScene(common + "--gl-loader=egl-proc --oracle " + (dir_ / "proc.oracle").string() +
                            " --dump-dir " + (dir_ / "proc").string());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path frameFile(const std::string& run, int n) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06d.ppm", n);
    return dir_ / run / name;
  }

  static fs::path dir_;
  static int status_direct_, status_again_, status_proc_;
};
fs::path SceneRun::dir_;
int SceneRun::status_direct_ = -1, SceneRun::status_again_ = -1, SceneRun::status_proc_ = -1;

TEST_F(SceneRun, RunsAndIsDeterministicWithBothLoaders) {
  ASSERT_EQ(status_direct_, 0);
  ASSERT_EQ(status_again_, 0);
  ASSERT_EQ(status_proc_, 0);
  for (int n = 0; n < kFrames; ++n) {
    const std::string a = readFile(frameFile("direct", n));
    ASSERT_EQ(a.size(), std::string("P6\n160 120\n255\n").size() + kWidth * kHeight * 3) << "frame " << n;
    EXPECT_EQ(a, readFile(frameFile("again", n))) << "frame " << n << " differs between identical runs";
    EXPECT_EQ(a, readFile(frameFile("proc", n))) << "frame " << n << " differs between GL loaders";
  }
  EXPECT_EQ(readFile(dir_ / "direct.oracle"), readFile(dir_ / "proc.oracle"));
  // Consecutive frames differ: things move.
  EXPECT_NE(readFile(frameFile("direct", 0)), readFile(frameFile("direct", 1)));
}

TEST_F(SceneRun, OracleDescribesTheScene) {
  ASSERT_EQ(status_direct_, 0);
  const Oracle oracle = readOracle((dir_ / "direct.oracle").string());
  EXPECT_EQ(oracle.width, kWidth);
  EXPECT_EQ(oracle.height, kHeight);
  ASSERT_EQ(oracle.frames.size(), static_cast<size_t>(kFrames));
  for (const OracleFrame& f : oracle.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.number));
    EXPECT_DOUBLE_EQ(f.time_s, f.number / 15.0);
    // The documented convention: view = inverse(camera body pose) with the body -> GL axis change,
    // i.e. exactly what the core's ego-motion recovers.
    const EgoPose pose = egoPoseFromView(f.view, f.time_s);
    EXPECT_LT((pose.map_from_body.matrix() - f.map_from_camera_body).cwiseAbs().maxCoeff(), 1e-4);

    std::map<uint32_t, GlMatrix> world_of_object;
    std::map<uint32_t, std::set<std::string>> parts_of_object;
    std::map<std::string, std::set<uint32_t>> objects_of_mesh;
    int skinned = 0;
    for (const OracleDraw& d : f.draws) {
      auto [it, inserted] = world_of_object.emplace(d.object_id, d.world);
      EXPECT_TRUE(inserted || it->second == d.world) << "parts of object " << d.object_id << " differ in world matrix";
      parts_of_object[d.object_id].insert(d.part);
      objects_of_mesh[d.mesh].insert(d.object_id);
      if (d.skinned) {
        ++skinned;
        EXPECT_EQ(d.class_id, 20u);
        EXPECT_EQ(d.bones.size(), 3u);
      }
    }
    EXPECT_EQ(skinned, 1);
    // Distinct objects never share a world matrix (that is how instances are found).
    for (auto a = world_of_object.begin(); a != world_of_object.end(); ++a)
      for (auto b = std::next(a); b != world_of_object.end(); ++b)
        EXPECT_NE(a->second, b->second) << "objects " << a->first << " and " << b->first;
    // A car of six parts; a mesh drawn for two objects; the transparent rain last.
    size_t most_parts = 0;
    for (const auto& [id, parts] : parts_of_object) most_parts = std::max(most_parts, parts.size());
    EXPECT_GE(most_parts, 6u);
    EXPECT_GE(objects_of_mesh.at("unit_box").size(), 2u);
    EXPECT_EQ(objects_of_mesh.at("car_wheel_fl").size(), 2u);
    ASSERT_FALSE(f.draws.empty());
    EXPECT_EQ(f.draws.back().class_id, 0u);
    EXPECT_EQ(f.draws.back().part, "streaks");
  }
  // Cars, camera and the person's bones move.
  const OracleFrame& first = oracle.frames.front();
  const OracleFrame& last = oracle.frames.back();
  EXPECT_NE(first.view, last.view);
  for (size_t i = 0; i < first.draws.size(); ++i)
    if (first.draws[i].class_id == 24 || first.draws[i].skinned) {
      EXPECT_NE(first.draws[i].world, last.draws[i].world) << "draw " << i;
    }
}

TEST_F(SceneRun, CarBodyIsWhereTheOracleSaysItIs) {
  ASSERT_EQ(status_direct_, 0);
  const Oracle oracle = readOracle((dir_ / "direct.oracle").string());
  const OracleFrame& f = oracle.frames.at(0);
  const std::string ppm = readFile(frameFile("direct", 0));
  const size_t header = std::string("P6\n160 120\n255\n").size();
  // The first car's body (red): project the centre of its box (model (0, 0, 0.7)) into the image.
  for (const OracleDraw& d : f.draws) {
    if (d.part != "body" || d.class_id != 24) continue;
    const Eigen::Vector4f clip = f.projection * f.view * d.world * Eigen::Vector4f(0, 0, 0.7f, 1);
    const int u = static_cast<int>((clip.x() / clip.w() + 1) / 2 * kWidth);
    const int v = static_cast<int>((1 - clip.y() / clip.w()) / 2 * kHeight);
    ASSERT_TRUE(u >= 0 && u < int(kWidth) && v >= 0 && v < int(kHeight)) << u << "," << v;
    const unsigned char* p = reinterpret_cast<const unsigned char*>(ppm.data()) + header + (v * kWidth + u) * 3;
    EXPECT_GT(p[0], 2 * p[1]) << "pixel " << u << "," << v << " is not the red car: " << int(p[0]) << " "
                              << int(p[1]) << " " << int(p[2]);
    return;
  }
  FAIL() << "no car body in frame 0";
}

TEST(SceneOptions, BadValuesExitWithTwo) {
  EXPECT_EQ(runScene("--frames 0"), 2);
  EXPECT_EQ(runScene("--width abc"), 2);
  EXPECT_EQ(runScene("--fps -3"), 2);
  EXPECT_EQ(runScene("--gl-loader glx"), 2);
  EXPECT_EQ(runScene("--no-such-option"), 2);
  EXPECT_EQ(runScene("--help"), 0);
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
