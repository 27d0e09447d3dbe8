// libFuzzer target: an arbitrary file as a sequence's done-marker. It must be read or end in
// std::runtime_error naming the file and line.
// Seeds: a marker written by writeSequenceMarker.
#include "fuzz_support.h"
#include "viper/dataset/sequence_marker.h"

#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  SequenceMarker marker;
  marker.frames = 30;
  marker.files = {{"train/img/001/001_00000.png", std::string(64, 'a')},
                  {"train/camera/001.csv", "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef"}};
  writeSequenceMarker(dir + "/001.done", marker);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".done");
  try {
    (void)viper::dataset::readSequenceMarker(path);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
