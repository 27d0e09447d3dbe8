#include "deflate_writers.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace viper::dataset::detail {

std::string temporaryPath(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
}

void writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes, const char* what,
                         FileDigests* digests) {
  const std::string tmp = temporaryPath(path);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (file == nullptr) throw std::runtime_error(path + ": cannot write " + what + ": " + std::strerror(errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size() && std::fflush(file) == 0;
  const int saved = errno;
  if (std::fclose(file) != 0 || !ok) {
    const int e = ok ? errno : saved;
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write " + what + ": " + std::strerror(e));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write " + what + ": rename failed: " + std::strerror(e));
  }
  if (digests) digests->record(path, bytes.size(), sha256Hex(bytes.data(), bytes.size()));
}

}  // namespace viper::dataset::detail
