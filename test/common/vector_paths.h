// For tests that compare the vector paths of a kernel (instructions.h) with its scalar path.
#pragma once

#include "viper/ground_truth/instructions.h"

#include <cstddef>
#include <cstring>
#include <vector>

namespace viper {
namespace test {

/// The vector paths this CPU has.
inline std::vector<Instructions> vectorPaths() {
  std::vector<Instructions> paths;
  for (Instructions i : {Instructions::kAvx2, Instructions::kAvx512, Instructions::kAvx512Vbmi})
    if (instructionsUsed(i) == i) paths.push_back(i);
  return paths;
}

inline const char* pathName(Instructions i) {
  return i == Instructions::kAvx512Vbmi ? "avx512vbmi"
         : i == Instructions::kAvx512   ? "avx512"
         : i == Instructions::kAvx2     ? "avx2"
                                        : "scalar";
}

/// Index of the first of n elements whose bytes differ (so NaNs compare by their bits), or -1.
template <typename T>
long firstDifference(const T* a, const T* b, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (std::memcmp(a + i, b + i, sizeof(T)) != 0) return static_cast<long>(i);
  return -1;
}

}  // namespace test
}  // namespace viper
