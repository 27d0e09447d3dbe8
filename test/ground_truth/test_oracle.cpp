// Oracle files: a written file (meshes included) reads back bit-identical, version 1 files still
// read, and malformed files are rejected with the file name and line.
#include "viper/ground_truth/oracle.h"

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

// A mesh with `vertices` random positions (several magnitudes), random triangles and, if
// `bones` > 0, random skin over that many bones.
OracleMesh makeMesh(std::mt19937& rng, const std::string& name, uint32_t vertices, uint32_t bones) {
  std::uniform_real_distribution<float> mantissa(-1.f, 1.f);
  std::uniform_int_distribution<int> exponent(-12, 12);
  std::uniform_int_distribution<uint32_t> vertex(0, vertices - 1);
  OracleMesh m;
  m.name = name;
  for (uint32_t i = 0; i < 3 * vertices; ++i) m.positions_xyz.push_back(std::ldexp(mantissa(rng), exponent(rng)));
  for (uint32_t i = 0; i < 3 * 2 * vertices; ++i) m.indices.push_back(vertex(rng));
  if (bones > 0) {
    std::uniform_int_distribution<uint32_t> bone(0, bones - 1);
    std::uniform_real_distribution<float> weight(0.f, 1.f);
    for (uint32_t i = 0; i < 4 * vertices; ++i) {
      m.bone_ids.push_back(bone(rng));
      m.bone_weights.push_back(weight(rng) / 3.f);
    }
    m.bone_ids[0] = bones - 1;  // the highest bone is used
  }
  return m;
}

void expectSameMesh(const OracleMesh& a, const OracleMesh& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.positions_xyz, b.positions_xyz) << a.name;  // float ==: bit-identical (no NaN)
  EXPECT_EQ(a.indices, b.indices) << a.name;
  EXPECT_EQ(a.bone_ids, b.bone_ids) << a.name;
  EXPECT_EQ(a.bone_weights, b.bone_weights) << a.name;
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
const char* kHeader2 = "viper_oracle 2\nsize 64 48\n";
const char* kCamera =
    "view 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
    "projection 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
    "camera_pose 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n";
const char* kWorld = "world 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n";

TEST(Oracle, RoundTripIsExact) {
  std::mt19937 rng(42);
  const std::vector<OracleFrame> frames = {makeFrame(rng, 0), makeFrame(rng, 1), makeFrame(rng, 5)};
  const std::vector<OracleMesh> meshes = {makeMesh(rng, "car_wheel_fl", 50, 0), makeMesh(rng, "person_tube", 40, 3),
                                          makeMesh(rng, "unused_box", 8, 0)};
  const std::string path = tempPath("round_trip.oracle");
  {
    OracleWriter writer(path, 1920, 1080);
    EXPECT_FALSE(writer.hasMesh("car_wheel_fl"));
    writer.writeMesh(meshes[0]);
    writer.writeMesh(meshes[1]);
    EXPECT_TRUE(writer.hasMesh("car_wheel_fl"));
    writer.write(frames[0]);
    writer.writeMesh(meshes[2]);  // between frames
    writer.write(frames[1]);
    writer.write(frames[2]);
  }
  const Oracle read = readOracle(path);
  std::remove(path.c_str());
  EXPECT_EQ(read.version, 2);
  ASSERT_EQ(read.meshes.size(), meshes.size());
  for (const OracleMesh& m : meshes) {
    ASSERT_NE(read.mesh(m.name), nullptr) << m.name;
    expectSameMesh(m, *read.mesh(m.name));
  }
  EXPECT_TRUE(read.mesh("car_wheel_fl")->positions_xyz.size() == 150 && !read.mesh("car_wheel_fl")->skinned());
  EXPECT_TRUE(read.mesh("person_tube")->skinned());
  EXPECT_EQ(read.mesh("nothing"), nullptr);
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
  EXPECT_EQ(o.version, 1);
  EXPECT_EQ(o.width, 64u);
  EXPECT_EQ(o.height, 48u);
  EXPECT_TRUE(o.frames.empty());
  EXPECT_TRUE(o.meshes.empty());
}

TEST(Oracle, Version1FilesReadWithoutMeshes) {
  // A version 1 frame names meshes that have no record: allowed there.
  std::istringstream in(std::string(kHeader) + "frame 0 0 1\n" + kCamera + "draw 0 6 24 body car_body 0 0\n" + kWorld);
  const Oracle o = parseOracle(in, "v1.oracle");
  EXPECT_EQ(o.version, 1);
  ASSERT_EQ(o.frames.size(), 1u);
  EXPECT_EQ(o.frames[0].draws.at(0).mesh, "car_body");
  EXPECT_TRUE(o.meshes.empty());
}

TEST(Oracle, HandWrittenMeshParses) {
  std::istringstream in(std::string(kHeader2) +
                        "mesh tri 3 1 0  # one triangle\nv 0 0 0\nv 1 0 0\nv 0 1.5 0\nt 0 1 2\n"
                        "mesh tube 2 0 1\nv 0 0 0 0 1 0 0 0.25 0.75 0 0\nv 0 0 2 1 1 1 1 1 0 0 0\n"
                        "frame 0 0 2\n" + kCamera + "draw 0 6 24 body tri 0 0\n" + kWorld +
                        "draw 1 7 20 body tube 1 2\n" + kWorld + "bone " + (kWorld + 6) + "bone " + (kWorld + 6));
  const Oracle o = parseOracle(in, "hand.oracle");
  ASSERT_NE(o.mesh("tri"), nullptr);
  EXPECT_EQ(o.mesh("tri")->positions_xyz, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1.5f, 0}));
  EXPECT_EQ(o.mesh("tri")->indices, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_NE(o.mesh("tube"), nullptr);
  EXPECT_EQ(o.mesh("tube")->vertexCount(), 2u);
  EXPECT_EQ(o.mesh("tube")->bone_ids, (std::vector<uint32_t>{0, 1, 0, 0, 1, 1, 1, 1}));
  EXPECT_EQ(o.mesh("tube")->bone_weights, (std::vector<float>{0.25f, 0.75f, 0, 0, 1, 0, 0, 0}));
  EXPECT_EQ(o.frames.at(0).draws.at(1).bones.size(), 2u);
}

TEST(Oracle, BadMeshRecordsNameFileAndLine) {
  const std::string frame = std::string("frame 0 0 1\n") + kCamera;
  // Meshes are a version 2 record.
  EXPECT_NE(expectParseError(std::string(kHeader) + "mesh tri 0 0 0\n").find("bad.oracle:3: expected 'frame', got 'mesh'"),
            std::string::npos);
  // Wrong number of header values, a vertex line missing a coordinate, a truncated mesh.
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tri 3 1\n").find("bad.oracle:3: 'mesh' needs 4 values"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tri 3 1 0\nv 0 0 0\nv 1 0\n")
                .find("bad.oracle:5: 'v' needs 3 values, got 2"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tri 3 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
                .find("bad.oracle:6: unexpected end of file, expected 't'"),
            std::string::npos);
  // A skinned vertex needs 4 ids and 4 weights; ids are integers.
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tube 1 0 1\nv 0 0 0 0 0 0 0 1 0 0\n")
                .find("bad.oracle:4: 'v' needs 11 values, got 10"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tube 1 0 1\nv 0 0 0 0.5 0 0 0 1 0 0 0\n")
                .find("bad.oracle:4: '0.5' is not a non-negative integer"),
            std::string::npos);
  // A coordinate that is not finite; an index past the vertices.
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tri 1 0 0\nv 0 nan 0\n")
                .find("bad.oracle:4: 'nan' is not a finite number"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tri 3 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nt 0 1 3\n")
                .find("bad.oracle:7: '3' is out of range (max 2)"),
            std::string::npos);
  // A name given twice.
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh e 1 0 0\nv 0 0 0\nmesh e 1 0 0\nv 0 0 0\n")
                .find("bad.oracle:5: mesh e appears twice"),
            std::string::npos);
  // In version 2 a draw's mesh must come before its frame, with skin for a skinned draw and
  // enough bones for its ids.
  EXPECT_NE(expectParseError(std::string(kHeader2) + frame + "draw 0 1 3 body box 0 0\n" + kWorld)
                .find("bad.oracle:7: draw 0: mesh box has no mesh record before this frame"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tube 1 0 0\nv 0 0 0\n" + frame +
                             "draw 0 1 20 body tube 1 1\n" + kWorld + "bone " + (kWorld + 6))
                .find("bad.oracle:9: draw 0: skinned draw of mesh tube, which has no bone weights"),
            std::string::npos);
  EXPECT_NE(expectParseError(std::string(kHeader2) + "mesh tube 1 0 1\nv 0 0 0 0 2 0 0 0.5 0.5 0 0\n" + frame +
                             "draw 0 1 20 body tube 1 2\n" + kWorld + "bone " + (kWorld + 6) + "bone " + (kWorld + 6))
                .find("bad.oracle:9: draw 0: mesh tube uses bone 2 but the draw has 2 bones"),
            std::string::npos);
}

TEST(Oracle, BadFilesNameFileAndLine) {
  EXPECT_NE(expectParseError("hello 1\n").find("bad.oracle:1: not an oracle file"), std::string::npos);
  EXPECT_NE(expectParseError("viper_oracle 3\nsize 1 1\n").find("bad.oracle:1: unsupported oracle version"),
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

TEST(Oracle, WriterRejectsInconsistentMeshes) {
  std::mt19937 rng(3);
  const std::string path = tempPath("reject_mesh.oracle");
  OracleWriter writer(path, 8, 8);
  OracleMesh m = makeMesh(rng, "bad name", 4, 0);
  EXPECT_THROW(writer.writeMesh(m), std::invalid_argument);
  m = makeMesh(rng, "box", 4, 0);
  m.indices.back() = 4;  // past the vertices
  EXPECT_THROW(writer.writeMesh(m), std::invalid_argument);
  m = makeMesh(rng, "box", 4, 0);
  m.positions_xyz.pop_back();
  EXPECT_THROW(writer.writeMesh(m), std::invalid_argument);
  m = makeMesh(rng, "box", 4, 0);
  m.positions_xyz[1] = std::nanf("");
  EXPECT_THROW(writer.writeMesh(m), std::invalid_argument);
  m = makeMesh(rng, "tube", 4, 2);
  m.bone_weights.pop_back();
  EXPECT_THROW(writer.writeMesh(m), std::invalid_argument);
  EXPECT_FALSE(writer.hasMesh("box"));
  writer.writeMesh(makeMesh(rng, "box", 4, 0));
  EXPECT_THROW(writer.writeMesh(makeMesh(rng, "box", 4, 0)), std::invalid_argument);  // twice
  std::remove(path.c_str());
}

TEST(Oracle, WriterRejectsInconsistentFrames) {
  std::mt19937 rng(1);
  const std::string path = tempPath("reject.oracle");
  {
    // Meshes must come first.
    OracleWriter writer(path, 8, 8);
    EXPECT_THROW(writer.write(makeFrame(rng, 2)), std::invalid_argument);
  }
  {
    // A skinned draw needs a skinned mesh ...
    OracleWriter writer(path, 8, 8);
    writer.writeMesh(makeMesh(rng, "car_wheel_fl", 4, 0));
    writer.writeMesh(makeMesh(rng, "person_tube", 4, 0));
    EXPECT_THROW(writer.write(makeFrame(rng, 2)), std::invalid_argument);
  }
  {
    // ... whose bone ids the draw's bones cover (the frame's skinned draw has 3 bones).
    OracleWriter writer(path, 8, 8);
    writer.writeMesh(makeMesh(rng, "car_wheel_fl", 4, 0));
    writer.writeMesh(makeMesh(rng, "person_tube", 4, 4));
    EXPECT_THROW(writer.write(makeFrame(rng, 2)), std::invalid_argument);
  }
  OracleWriter writer(path, 8, 8);
  writer.writeMesh(makeMesh(rng, "car_wheel_fl", 4, 0));
  writer.writeMesh(makeMesh(rng, "person_tube", 4, 3));
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
