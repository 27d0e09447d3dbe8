// libFuzzer target: arbitrary bytes as an .npy array (the members of VIPER's flow .npz). Decoding
// must succeed or end in std::runtime_error naming the input; a decoded array holds exactly the
// bytes its shape and type announce.
// Seeds: arrays written by encodeNpy (float16 and float32, C and Fortran order, 0-d and 2-d).
#include "fuzz_support.h"
#include "viper/dataset/npy.h"

#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  using viper::dataset::NpyArray;
  const NpyArray arrays[] = {
      {"<f2", false, {2, 3}, std::vector<uint8_t>(12, 0x3c)},
      {">f4", true, {3, 2}, std::vector<uint8_t>(24, 0x41)},
      {"<f4", false, {}, std::vector<uint8_t>(4, 0)},
      {"|u1", false, {0, 5}, {}},
  };
  int n = 0;
  for (const NpyArray& a : arrays) writeBytes(dir + "/array" + std::to_string(n++) + ".npy", encodeNpy(a));
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace viper::dataset;
  try {
    (void)decodeNpyHeader(data, size, "fuzz-input.npy");
  } catch (const std::runtime_error&) {
  }
  try {
    const NpyArray array = decodeNpy(data, size, "fuzz-input.npy");
    if (array.data.size() != npyElementCount(array.shape) * npyItemSize(array.descr)) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
