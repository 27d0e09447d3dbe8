// What every fuzz target shares: a scratch file for readers that take a path, and the seed mode.
// A target defines LLVMFuzzerTestOneInput and writeSeeds(); run with VIPER_FUZZ_SEEDS=DIR, its
// binary writes its seeds into DIR (with the package's own writers) and exits instead of fuzzing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::fuzz {

/// Writes `size` bytes to this process's scratch file `<tmp>/viper_fuzz_<pid><suffix>` (replacing
/// it) and returns its path. The files are removed when the process exits.
std::string scratchFile(const uint8_t* data, size_t size, const std::string& suffix);

/// Writes `bytes` to `path`. Throws std::runtime_error naming the path on failure.
void writeBytes(const std::string& path, const std::string& bytes);
void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes);

/// Defined by each target: writes its seed inputs into the folder `dir` (which exists).
void writeSeeds(const std::string& dir);

}  // namespace viper::fuzz
