// libFuzzer target: an arbitrary file as a VIPER camera CSV. Reading never throws for bad lines:
// each is left out with a problem `path:line: ...`, the intact lines kept.
// Seeds: camera files written by writeViperCameraCsv.
#include "fuzz_support.h"
#include "viper/dataset/viper_camera.h"

#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  std::vector<ViperCameraRow> rows(3);
  for (size_t i = 0; i < rows.size(); ++i) {
    rows[i].frame = 10 * i;
    rows[i].projection = {1.2, 0, 0, 0, 0, 1.6, 0, 0, 0, 0, -1.0002, -0.20002, 0, 0, -1, 0};
    rows[i].view[3] = -0.5 * i;
  }
  writeViperCameraCsv(dir + "/camera.csv", rows);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".csv");
  std::vector<std::string> problems;
  for (const auto& [frame, row] : viper::dataset::readViperCameraCsv(path, problems))
    if (row.frame != frame) __builtin_trap();
  for (const std::string& problem : problems)
    if (problem.rfind(path + ":", 0) != 0) __builtin_trap();
  return 0;
}
