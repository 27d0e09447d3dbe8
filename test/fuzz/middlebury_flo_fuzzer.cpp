// libFuzzer target: an arbitrary file as Middlebury .flo. It must be read or end in
// std::runtime_error naming the file; a flow read holds 2 * width * height values.
// Seeds: files written by writeMiddleburyFlo, with unknown (NaN) pixels.
#include "fuzz_support.h"
#include "viper/dataset/middlebury_flo.h"

#include <cmath>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  FlowImage flow;
  flow.width = 3;
  flow.height = 2;
  flow.uv = {0.5f, -1, NAN, 2, 3, 4, 1e12f, 0, 7, 8, -0.25f, 9};
  writeMiddleburyFlo(dir + "/flow.flo", flow);
  flow.width = 1;
  flow.height = 1;
  flow.uv = {1, 2};
  writeMiddleburyFlo(dir + "/pixel.flo", flow);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".flo");
  try {
    const viper::dataset::FlowImage flow = viper::dataset::readMiddleburyFlo(path);
    if (flow.uv.size() != 2 * flow.pixels()) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
