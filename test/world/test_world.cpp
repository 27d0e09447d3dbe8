// Tests of the `world` program: determinism, content (classes, objects, skinning, LOD) from its
// oracle file, the five conditions, and its command line. They run the built binary.
#include "world_run.h"

#include "viper/ground_truth/oracle.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <fstream>
#include <map>
#include <set>
#include <string>

using namespace viper::world_test;

namespace {
const char* kSmall = "--width 320 --height 180";

std::string matrixBytes(const viper::GlMatrix& m) {
  return std::string(reinterpret_cast<const char*>(m.data()), sizeof(float) * 16);
}

// The class ids with class_eval = 1 in the VIPER class table.
std::set<uint32_t> evaluatedClasses() {
  std::ifstream in(VIPER_CLASSES_CSV);
  std::set<uint32_t> out;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> cols;
    size_t start = 0;
    for (size_t comma; (comma = line.find(',', start)) != std::string::npos; start = comma + 1)
      cols.push_back(line.substr(start, comma - start));
    cols.push_back(line.substr(start));
    if (cols.size() >= 8 && cols[5] == "1") out.insert(uint32_t(std::stoul(cols[0])));
  }
  return out;
}
}  // namespace

TEST(World, SameSeedGivesIdenticalFramesOtherSeedDiffers) {
  const TempDir da, db, dc;
  const std::string a = da.path(), b = db.path(), c = dc.path();
  const std::string common = std::string(kSmall) + " --condition rain --frames 4 --dump-dir ";
  ASSERT_EQ(runWorld(common + a + " --seed 5", a + "/log"), 0);
  ASSERT_EQ(runWorld(common + b + " --seed 5", b + "/log"), 0);
  ASSERT_EQ(runWorld(common + c + " --seed 6", c + "/log"), 0);
  for (int f = 0; f < 4; ++f) {
    const Image ia = readPpm(framePath(a, f)), ib = readPpm(framePath(b, f)),
                ic = readPpm(framePath(c, f));
    EXPECT_EQ(hashImage(ia), hashImage(ib)) << "frame " << f;
    EXPECT_NE(hashImage(ia), hashImage(ic)) << "frame " << f;
  }
  // Frames of one run change over time (traffic, ego and rain move).
  EXPECT_NE(hashImage(readPpm(framePath(a, 0))), hashImage(readPpm(framePath(a, 3))));
}

class WorldOracle : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const TempDir dir;
    // The default sequence (150 frames, drive, day), in small frames.
    ASSERT_EQ(runWorld(std::string(kSmall) + " --oracle " + (dir / "oracle.txt"), dir / "log"), 0);
    oracle_ = new viper::Oracle(viper::readOracle(dir / "oracle.txt"));
  }
  static void TearDownTestSuite() { delete oracle_; }
  static viper::Oracle* oracle_;
};
viper::Oracle* WorldOracle::oracle_ = nullptr;

TEST_F(WorldOracle, EveryEvaluatedClassIsDrawn) {
  ASSERT_EQ(oracle_->frames.size(), 150u);
  std::map<uint32_t, std::set<uint32_t>> objects_of_class;
  for (const auto& frame : oracle_->frames)
    for (const auto& d : frame.draws) objects_of_class[d.class_id].insert(d.object_id);
  for (uint32_t c : {13u, 16u, 17u, 19u, 20u, 23u, 24u, 25u, 26u, 27u})
    EXPECT_GT(objects_of_class[c].size(), 0u) << "instance class " << c << " never drawn";
  const std::set<uint32_t> evaluated = evaluatedClasses();
  ASSERT_EQ(evaluated.size(), 23u);
  int drawn = 0;
  for (uint32_t c : evaluated) {
    EXPECT_GT(objects_of_class[c].size(), 0u) << "evaluated class " << c << " never drawn";
    drawn += objects_of_class[c].empty() ? 0 : 1;
  }
  EXPECT_EQ(drawn, 23);
  // Several instances of the common classes.
  EXPECT_GE(objects_of_class[20].size(), 10u);
  EXPECT_GE(objects_of_class[24].size(), 5u);
}

TEST_F(WorldOracle, PartsShareTheObjectMatrixAndObjectsDiffer) {
  for (const auto& frame : oracle_->frames) {
    std::map<uint32_t, std::string> matrix_of_object;
    std::map<std::string, uint32_t> object_of_matrix;
    for (const auto& d : frame.draws) {
      const std::string m = matrixBytes(d.world);
      auto it = matrix_of_object.find(d.object_id);
      if (it != matrix_of_object.end()) {
        ASSERT_EQ(it->second, m) << "frame " << frame.number << " object " << d.object_id
                                 << " part " << d.part << " has another matrix";
      } else {
        matrix_of_object[d.object_id] = m;
        auto other = object_of_matrix.find(m);
        ASSERT_TRUE(other == object_of_matrix.end())
            << "frame " << frame.number << " objects " << d.object_id << " and " << other->second
            << " share a world matrix";
        object_of_matrix[m] = d.object_id;
      }
    }
  }
}

TEST_F(WorldOracle, PeopleAreSkinnedAndVehiclesSwapLevelsOfDetail) {
  std::map<uint32_t, std::set<std::string>> vehicle_meshes;
  std::set<std::string> shared_meshes_by_class[32];
  size_t people = 0, moving_bones = 0;
  std::map<uint32_t, std::string> first_bones;
  for (const auto& frame : oracle_->frames)
    for (const auto& d : frame.draws) {
      if (d.class_id == 20) {
        ++people;
        ASSERT_TRUE(d.skinned);
        ASSERT_EQ(d.bones.size(), 11u);
        std::string bytes;
        for (const auto& b : d.bones) bytes += matrixBytes(b);
        auto it = first_bones.find(d.object_id);
        if (it == first_bones.end()) first_bones[d.object_id] = bytes;
        else if (it->second != bytes) ++moving_bones;
      } else {
        ASSERT_FALSE(d.skinned) << d.mesh;
      }
      if (d.class_id >= 23 && d.class_id <= 27) {
        vehicle_meshes[d.object_id].insert(d.mesh);
        shared_meshes_by_class[d.class_id].insert(d.mesh);
      }
    }
  EXPECT_GT(people, 0u);
  EXPECT_GT(moving_bones, 0u) << "no person's pose ever changed";
  int swapped = 0;
  for (const auto& [id, names] : vehicle_meshes) {
    bool lod0 = false, lod1 = false;
    for (const auto& n : names) {
      lod0 |= n.find("_lod0") != std::string::npos;
      lod1 |= n.find("_lod1") != std::string::npos;
    }
    swapped += lod0 && lod1;
  }
  EXPECT_GT(swapped, 0) << "no vehicle changed its level of detail";
  // Car and van share wheel and headlight meshes.
  EXPECT_TRUE(shared_meshes_by_class[24].count("headlights_std"));
  EXPECT_TRUE(shared_meshes_by_class[25].count("headlights_std"));
}

TEST_F(WorldOracle, VehiclesNeverOverlap) {
  // Vehicles follow their leader and stop for red lights, so no two are ever on top of each other
  // (centres closer than a car is wide), not even in intersections.
  for (const auto& frame : oracle_->frames) {
    std::map<uint32_t, Eigen::Vector2f> centre;
    for (const auto& d : frame.draws)
      if (d.class_id >= 23 && d.class_id <= 27) centre[d.object_id] = d.world.block<2, 1>(0, 3);
    for (auto a = centre.begin(); a != centre.end(); ++a)
      for (auto b = std::next(a); b != centre.end(); ++b)
        ASSERT_GT((a->second - b->second).norm(), 2.5f)
            << "frame " << frame.number << ": vehicles " << a->first << " and " << b->first;
  }
}

TEST(World, EgoModesSetCameraHeightAndMotion) {
  std::map<std::string, viper::Oracle> runs;
  for (const char* mode : {"drive", "ride", "walk"}) {
    const TempDir dir;
    ASSERT_EQ(runWorld(std::string(kSmall) + " --frames 30 --ego " + mode + " --oracle " + (dir / "o.txt"),
                       dir / "log"), 0) << mode;
    runs[mode] = viper::readOracle(dir / "o.txt");
  }
  auto height = [&](const char* mode) { return runs[mode].frames.back().map_from_camera_body(2, 3); };
  auto travelled = [&](const char* mode) {
    const auto& f = runs[mode].frames;
    return (f.back().map_from_camera_body.block<3, 1>(0, 3) - f.front().map_from_camera_body.block<3, 1>(0, 3)).norm();
  };
  EXPECT_NEAR(height("drive"), 1.5, 1e-3);
  EXPECT_LT(height("ride"), height("drive"));
  EXPECT_GT(height("walk"), height("drive"));
  // 2 s of simulated time: walking covers about 2.8 m, driving and riding much more.
  EXPECT_NEAR(travelled("walk"), 1.4 * 29 / 15.0, 0.1);
  EXPECT_GT(travelled("drive"), 5 * travelled("walk"));
  EXPECT_GT(travelled("ride"), 5 * travelled("walk"));
}

// Pixels whose brightness differs by more than 10 levels between two images.
int changedPixels(const Image& a, const Image& b) {
  int count = 0;
  for (size_t i = 0; i + 2 < a.rgb.size(); i += 3) {
    int da = a.rgb[i] + a.rgb[i + 1] + a.rgb[i + 2], db = b.rgb[i] + b.rgb[i + 1] + b.rgb[i + 2];
    count += std::abs(da - db) > 30;
  }
  return count;
}

TEST(World, EachConditionDiffersFromDay) {
  std::map<std::string, Image> frames, plain;
  for (const char* c : {"day", "sunset", "rain", "snow", "night"}) {
    for (bool effects : {true, false}) {
      const TempDir dir;
      ASSERT_EQ(runWorld(std::string(kSmall) + " --frames 2 --condition " + c + " --dump-dir " + dir.path().string() +
                             (effects ? "" : " --no-effects"),
                         dir / "log"), 0) << c;
      (effects ? frames : plain)[c] = readPpm(framePath(dir.path(), 1));
    }
  }
  const Image& day = frames["day"];
  const double day_mean = meanBrightness(day), day_contrast = contrast(day);
  const int pixels = day.width * day.height;
  for (const auto& [name, im] : frames)
    std::cout << name << ": mean " << meanBrightness(im) << " contrast " << contrast(im)
              << " red/blue " << redBlueRatio(im) << " effect pixels "
              << changedPixels(im, plain[name]) << "\n";
  EXPECT_LT(meanBrightness(frames["night"]), 0.6 * day_mean);
  EXPECT_LT(meanBrightness(frames["rain"]), 0.8 * day_mean);
  EXPECT_LT(contrast(frames["rain"]), 0.7 * day_contrast);
  EXPECT_GT(redBlueRatio(frames["sunset"]), 1.5 * redBlueRatio(day));
  EXPECT_LT(contrast(frames["snow"]), 0.8 * day_contrast);
  EXPECT_GT(meanBrightness(frames["snow"]), 1.4 * day_mean);
  // Particles and glare: pixels that change when the effects are left out.
  EXPECT_EQ(changedPixels(day, plain["day"]), 0);
  EXPECT_GT(changedPixels(frames["rain"], plain["rain"]), pixels / 200);
  EXPECT_GT(changedPixels(frames["snow"], plain["snow"]), pixels / 200);
  EXPECT_GT(changedPixels(frames["sunset"], plain["sunset"]), pixels / 10);
  // Without the effects the other conditions still differ from day everywhere.
  EXPECT_GT(changedPixels(plain["night"], plain["day"]), pixels / 2);
}

TEST(World, BadOptionsExitWithTwo) {
  const TempDir dir;
  const std::string log = dir / "log";
  EXPECT_EQ(runWorld("--condition fog", log), 2);
  EXPECT_EQ(runWorld("--width 0", log), 2);
  EXPECT_EQ(runWorld("--fps abc", log), 2);
  EXPECT_EQ(runWorld("--ego fly", log), 2);
  EXPECT_EQ(runWorld("--frames", log), 2);
  EXPECT_EQ(runWorld("--no-such-option", log), 2);
  EXPECT_EQ(runWorld("--help", log), 0);
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
