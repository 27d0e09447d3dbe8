#include "viper/dataset/float16.h"

namespace viper::dataset {

size_t floatsToHalves(const float* in, size_t n, uint16_t* out) {
  size_t overflowed = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint16_t h = floatToHalf(in[i]);
    out[i] = h;
    uint32_t x;
    std::memcpy(&x, &in[i], sizeof x);
    // Infinite half from a finite float: exponent bits all ones in h, but not in the input.
    overflowed += ((h & 0x7fffu) == 0x7c00u) & ((x & 0x7f800000u) != 0x7f800000u);
  }
  return overflowed;
}

void halvesToFloats(const uint16_t* in, size_t n, float* out) {
  for (size_t i = 0; i < n; ++i) out[i] = halfToFloat(in[i]);
}

}  // namespace viper::dataset
