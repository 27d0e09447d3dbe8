// libFuzzer target: an arbitrary file as a dataset plan (YAML). It must be read or end in
// std::runtime_error naming the file; a plan read has only valid, distinct sequences.
// Seeds: the tiny and small presets written by writePlan.
#include "fuzz_support.h"
#include "viper/dataset/dataset_plan.h"

#include <set>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  writePlan(dir + "/tiny.yaml", presetPlan("tiny"));
  writePlan(dir + "/small.yaml", presetPlan("small"));
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".yaml");
  try {
    const viper::dataset::DatasetPlan plan = viper::dataset::readPlan(path);
    std::set<std::string> ids;
    for (const auto& s : plan.sequences)
      if (s.frames == 0 || s.id.empty() || !ids.insert(s.split + "/" + s.id).second) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
