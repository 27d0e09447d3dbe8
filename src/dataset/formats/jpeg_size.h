// The size a JPEG declares, read from its header with libjpeg before anything is decoded (private
// to viper_dataset).
#pragma once

#include <cstddef>
#include <cstdint>

namespace viper::dataset {

struct JpegSize {
  uint32_t width = 0;
  uint32_t height = 0;
};

/// Reads the frame header of the JPEG in `bytes` (markers up to the first scan). Throws
/// std::runtime_error with libjpeg's reason (without a path) if the header is missing or damaged.
JpegSize readJpegSize(const uint8_t* bytes, size_t size);

}  // namespace viper::dataset
