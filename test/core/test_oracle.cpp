// Oracle files: a written file reads back bit-identical, and malformed files are rejected with the
// file name and line.
#include "viper/core/oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>

namespace viper {
namespace {

GlMatrix randomMatrix(std::mt19937& rng) {
  // Values that do not print exactly in few digits, over several magnitudes.
  std::uniform_real_distribution<float> mantissa(-1.f, 1.f);
  std::uniform_int_distribution<int> exponent(-20, 20);
  GlMatrix m;
  for (int i = 0; i < 16; ++i) m.data()[i] = std::ldexp(mantissa(rng), exponent(rng));
  return m;
}

OracleFrame makeFrame(std::mt19937& rng, uint64_t number) {
  OracleFrame f;
  f.number = number;
  f.time_s = number / 15.0;
  f.view = randomMatrix(rng);
  f.projection = randomMatrix(rng);
  f.map_from_camera_body = randomMatrix(rng).cast<double>() / 3.0;
  OracleDraw rigid;
  rigid.index = 0;
  rigid.object_id = 7;
  rigid.class_id = 24;
  rigid.part = "wheel_fl";
  rigid.mesh = "car_wheel_fl";
  rigid.world = randomMatrix(rng);
  OracleDraw skinned;
  skinned.index = 1;
  skinned.object_id = 0;
  skinned.class_id = 20;
  skinned.part = "body";
  skinned.mesh = "person_tube";
  skinned.world = randomMatrix(rng);
  skinned.skinned = true;
  skinned.bones = {randomMatrix(rng), randomMatrix(rng), randomMatrix(rng)};
  f.draws = {rigid, skinned};
  return f;
}

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "viper_oracle_" + std::to_string(::getpid()) + "_" + name;
}

std::string expectParseError(const std::string& text) {
  std::istringstream in(text);
  try {
    parseOracle(in, "bad.oracle");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

const char* kHeader = "viper_oracle 1\nsize 64 48\n";
const char* kCamera =
    "view 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
    "projection 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
    "camera_pose 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n";
const char* kWorld = "world 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n";

TEST(Oracle, RoundTripIsExact) {
  std::mt19937 rng(42);
  const std::vector<OracleFrame> frames = {makeFrame(rng, 0), makeFrame(rng, 1), makeFrame(rng, 5)};
  const std::string path = tempPath("round_trip.oracle");
  {
    OracleWriter writer(path, 1920, 1080);
    for (const OracleFrame& f : frames) writer.write(f);
  }
  const Oracle read = readOracle(path);
  std::remove(path.c_str());
  EXPECT_EQ(read.width, 1920u);
  EXPECT_EQ(read.height, 1080u);
  ASSERT_EQ(read.frames.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const OracleFrame& a = frames[i];
    const OracleFrame& b = read.frames[i];
    EXPECT_EQ(a.number, b.number);
    EXPECT_EQ(a.time_s, b.time_s) << "frame " << i;
    EXPECT_EQ(a.view, b.view) << "frame " << i;
    EXPECT_EQ(a.projection, b.projection) << "frame " << i;
    EXPECT_EQ(a.map_from_camera_body, b.map_from_camera_body) << "frame " << i;
    ASSERT_EQ(a.draws.size(), b.draws.size());
    for (size_t d = 0; d < a.draws.size(); ++d) {
      SCOPED_TRACE("frame " + std::to_string(i) + " draw " + std::to_string(d));
      EXPECT_EQ(a.draws[d].index, b.draws[d].index);
      EXPECT_EQ(a.draws[d].object_id, b.draws[d].object_id);
      EXPECT_EQ(a.draws[d].class_id, b.draws[d].class_id);
      EXPECT_EQ(a.draws[d].part, b.draws[d].part);
      EXPECT_EQ(a.draws[d].mesh, b.draws[d].mesh);
      EXPECT_EQ(a.draws[d].world, b.draws[d].world);
      EXPECT_EQ(a.draws[d].skinned, b.draws[d].skinned);
      ASSERT_EQ(a.draws[d].bones.size(), b.draws[d].bones.size());
      for (size_t k = 0; k < a.draws[d].bones.size(); ++k) EXPECT_EQ(a.draws[d].bones[k], b.draws[d].bones[k]);
    }
  }
}

TEST(Oracle, EmptySequenceAndCommentsParse) {
  std::istringstream in(std::string("# written by hand\n") + kHeader + "\n# no frames\n");
  const Oracle o = parseOracle(in, "hand.oracle");
  EXPECT_EQ(o.width, 64u);
  EXPECT_EQ(o.height, 48u);
  EXPECT_TRUE(o.frames.empty());
}

TEST(Oracle, BadFilesNameFileAndLine) {
  EXPECT_NE(expectParseError("hello 1\n").find("bad.oracle:1: not an oracle file"), std::string::npos);
  EXPECT_NE(expectParseError("viper_oracle 2\nsize 1 1\n").find("bad.oracle:1: unsupported oracle version"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader) + "frame 0 0 1\n" + kCamera).find("bad.oracle:6: unexpected end"),
            std::string::npos);
  // A number that is not one, on the view line.
  EXPECT_NE(expectParseError(std::string(kHeader) + "frame 0 0 0\nview 1 0 0 0 0 1 0 0 0 0 1 0 0 0 x 1\n")
                .find("bad.oracle:4: 'x' is not a finite number"),
            std::string::npos);
  // Class id out of range.
  EXPECT_NE(expectParseError(std::string(kHeader) + "frame 0 0 1\n" + kCamera + "draw 0 1 32 body box 0 0\n" + kWorld)
                .find("bad.oracle:7: '32' is out of range"),
            std::string::npos);
  // Draw indices must count up from 0.
  EXPECT_NE(expectParseError(std::string(kHeader) + "frame 0 0 1\n" + kCamera + "draw 1 1 3 body box 0 0\n" + kWorld)
                .find("bad.oracle:7: draw index 1, expected 0"),
            std::string::npos);
  // A skinned draw must carry bones.
  EXPECT_NE(expectParseError(std::string(kHeader) + "frame 0 0 1\n" + kCamera + "draw 0 1 20 body tube 1 0\n" + kWorld)
                .find("bad.oracle:7: skinned draw without bones"),
            std::string::npos);
  // Frame numbers must increase.
  const std::string empty_frame = std::string("frame 3 0 0\n") + kCamera;
  EXPECT_NE(expectParseError(std::string(kHeader) + empty_frame + empty_frame).find("bad.oracle:7: frame number 3"),
            std::string::npos);
}

TEST(Oracle, MissingFileNamesIt) {
  try {
    readOracle("/nonexistent/dir/x.oracle");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.oracle"), std::string::npos) << e.what();
  }
}

TEST(Oracle, WriterRejectsInconsistentFrames) {
  std::mt19937 rng(1);
  const std::string path = tempPath("reject.oracle");
  OracleWriter writer(path, 8, 8);
  OracleFrame f = makeFrame(rng, 2);
  f.draws[0].part = "front wheel";
  EXPECT_THROW(writer.write(f), std::invalid_argument);
  f = makeFrame(rng, 2);
  f.draws[1].bones.clear();
  EXPECT_THROW(writer.write(f), std::invalid_argument);
  writer.write(makeFrame(rng, 2));
  EXPECT_THROW(writer.write(makeFrame(rng, 2)), std::invalid_argument);  // number must increase
  std::remove(path.c_str());
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
