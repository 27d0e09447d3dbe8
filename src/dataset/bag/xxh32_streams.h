// XXH32 (seed 0, https://github.com/Cyan4973/xxHash/blob/dev/doc/xxhash_spec.md) of several byte
// streams at once, each given as pieces in order: an LZ4 chunk's content checksum over the bytes
// decompressed into the chunk and into a sink's storage. One stream's XXH32 waits on a chain of
// add, rotate and multiply for every 16 bytes (libxxhash: 7 GB/s here, bound by multiplies); two
// or more streams side by side in one vector register hide that chain's latency (two 8 MB streams:
// 2.3 ms with libxxhash, 0.9 ms side by side, on a Zen 4). AVX-512 (VL) where the CPU has it, two
// streams at a time with AVX2 (no rotate instruction), else each stream alone; the same hash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper::dataset::detail {

struct BytePiece {
  const uint8_t* data;
  size_t size;
};

/// XXH32 with seed 0 of each stream (the concatenation of its pieces) into `hashes`.
void xxh32Streams(const std::vector<const std::vector<BytePiece>*>& streams, uint32_t* hashes);

/// The side-by-side kernel this CPU runs, "avx512", "avx2" or "scalar" (for benchmarks and tests).
const char* xxh32StreamsKernel();

}  // namespace viper::dataset::detail
