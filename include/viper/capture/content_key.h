// Content keys: stable 64-bit hashes that name resources (buffers, textures, programs, meshes)
// by their bytes, identical across runs and processes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace viper {

/// XXH3-64 of `size` bytes (seed 0). Never returns 0 for non-empty input (0 means "none").
uint64_t contentKey(const void* data, size_t size);
inline uint64_t contentKey(const std::string& bytes) { return contentKey(bytes.data(), bytes.size()); }

/// Combines keys in order (for keys built from several parts).
uint64_t combineKeys(uint64_t a, uint64_t b);

}  // namespace viper
