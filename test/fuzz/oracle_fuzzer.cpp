// libFuzzer target: arbitrary text as an oracle file (docs/oracle_format.md), which
// make_label_table reads. It must parse or end in std::runtime_error naming the source.
// Seeds: a version 2 file written by OracleWriter (a rigid and a skinned mesh, two frames).
#include "fuzz_support.h"
#include "viper/ground_truth/oracle.h"

#include <sstream>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  viper::OracleWriter writer(dir + "/seed.oracle", 4, 3);
  viper::OracleMesh rigid;
  rigid.name = "box";
  rigid.positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  rigid.indices = {0, 1, 2};
  writer.writeMesh(rigid);
  viper::OracleMesh skinned = rigid;
  skinned.name = "arm";
  skinned.bone_ids = {0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0};
  skinned.bone_weights = {1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0.25f, 0.75f, 0, 0};
  writer.writeMesh(skinned);
  for (uint64_t n = 0; n < 2; ++n) {
    viper::OracleFrame frame;
    frame.number = n;
    frame.time_s = n / 15.0;
    viper::OracleDraw a;
    a.index = 0;
    a.object_id = 3;
    a.class_id = 24;
    a.part = "body";
    a.mesh = "box";
    viper::OracleDraw b = a;
    b.index = 1;
    b.part = "arm";
    b.mesh = "arm";
    b.skinned = true;
    b.bones.assign(2, viper::GlMatrix::Identity());
    frame.draws = {a, b};
    writer.write(frame);
  }
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    (void)viper::parseOracle(in, "fuzz-input");
  } catch (const std::runtime_error&) {
  }
  return 0;
}
