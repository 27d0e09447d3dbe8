// Binary PPM (P6) output for the frame dumps of our GL programs (--dump-dir).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace gl_common {

/// Writes rgb8 pixels (top row first) as a P6 file. Throws std::runtime_error naming the file on
/// failure, std::invalid_argument if the pixel count does not match the size.
void writePpm(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgb);

}  // namespace gl_common
}  // namespace viper
