#include "ppm.h"

#include <fstream>
#include <stdexcept>

namespace viper {
namespace gl_common {

void writePpm(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgb) {
  if (rgb.size() != static_cast<size_t>(width) * height * 3)
    throw std::invalid_argument("writePpm " + path + ": pixel data does not match " + std::to_string(width) + "x" +
                                std::to_string(height));
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "P6\n" << width << ' ' << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(rgb.data()), static_cast<std::streamsize>(rgb.size()));
  if (!out.flush()) throw std::runtime_error(path + ": write error");
}

}  // namespace gl_common
}  // namespace viper
