// libFuzzer target: an arbitrary file as VIPER's flow .npz, through the zip reader (every entry
// read, CRC checked) and readViperFlow. Each must succeed or end in std::runtime_error naming the
// file; a flow read holds 2 * width * height values.
// Seeds: .npz files written by writeViperFlow, stored (numpy.savez) and deflated
// (savez_compressed), with invalid (NaN) pixels.
#include "fuzz_support.h"
#include "viper/dataset/viper_flow.h"

#include <cmath>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  FlowImage flow;
  flow.width = 4;
  flow.height = 3;
  for (size_t i = 0; i < flow.pixels() * 2; ++i) flow.uv.push_back(i % 5 == 0 ? NAN : 0.25f * i - 1);
  writeViperFlow(dir + "/stored.npz", flow, ZipWriteOptions{0});
  writeViperFlow(dir + "/deflated.npz", flow, ZipWriteOptions{6});
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace viper::dataset;
  const std::string path = viper::fuzz::scratchFile(data, size, ".npz");
  try {
    const ZipReader zip(path);
    for (const std::string& name : zip.names()) {
      try {
        (void)zip.read(name);
      } catch (const std::runtime_error&) {
      }
    }
  } catch (const std::runtime_error&) {
  }
  try {
    const FlowImage flow = readViperFlow(path);
    if (flow.uv.size() != 2 * flow.pixels()) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
