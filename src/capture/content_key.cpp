#include "viper/capture/content_key.h"

#include <xxhash.h>

namespace viper {

uint64_t contentKey(const void* data, size_t size) {
  if (size == 0) return 0;
  const uint64_t key = XXH3_64bits(data, size);
  return key == 0 ? 1 : key;
}

uint64_t combineKeys(uint64_t a, uint64_t b) {
  const uint64_t parts[2] = {a, b};
  return contentKey(parts, sizeof(parts));
}

}  // namespace viper
