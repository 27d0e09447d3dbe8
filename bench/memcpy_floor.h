// The floor the benchmarks set each kernel against: memcpy of the bytes it reads or writes.
#pragma once

#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

namespace viper {
namespace bench {

/// Copies `bytes` bytes once an iteration; reports the bytes a second.
inline void copyBytes(benchmark::State& state, size_t bytes) {
  std::vector<char> src(bytes, 1), dst(bytes);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), bytes);
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * bytes);
}

}  // namespace bench
}  // namespace viper
