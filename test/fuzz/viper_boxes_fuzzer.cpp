// libFuzzer target: an arbitrary file as a VIPER box CSV. Reading never throws for bad lines:
// each is left out with a problem `path:line: ...`, the intact lines kept, each with a class id
// in 0..255 and a non-negative instance id.
// Seeds: box files written by writeViperBoxesCsv.
#include "fuzz_support.h"
#include "viper/dataset/viper_boxes.h"

#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  ViperBoxRow car;
  car.class_id = 24;
  car.instance_id = 513;
  car.box_2d = {{3, 4, 10, 12}};
  car.box_3d = {{-1, -0.5, -2, 1, 0.5, 2}};
  car.model_to_camera[3] = 2.5;
  ViperBoxRow person = car;
  person.class_id = 19;
  person.instance_id = 7;
  writeViperBoxesCsv(dir + "/boxes.csv", {car, person});
  writeViperBoxesCsv(dir + "/none.csv", {});
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".csv");
  std::vector<std::string> problems;
  for (const viper::dataset::ViperBoxRow& row : viper::dataset::readViperBoxesCsv(path, problems))
    if (row.class_id < 0 || row.class_id > 255 || row.instance_id < 0) __builtin_trap();
  for (const std::string& problem : problems)
    if (problem.rfind(path + ":", 0) != 0) __builtin_trap();
  return 0;
}
