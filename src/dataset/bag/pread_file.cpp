#include "pread_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace viper::dataset::detail {

namespace {
constexpr size_t kWindow = 64 * 1024;  // a chunk's index records, or many connection records, at once
}

PreadFile::PreadFile(const std::string& path, const std::string& what) : path_(path), what_(what) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st;
  if (fd_ < 0 || ::fstat(fd_, &st) != 0) {
    const int error = errno;
    if (fd_ >= 0) ::close(fd_);
    throw std::runtime_error(path_ + ": " + what_ + ": " + std::strerror(error));
  }
  size_ = static_cast<uint64_t>(st.st_size);
  // Chunks are read front to back: a larger read-ahead.
  ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
}

PreadFile::~PreadFile() { ::close(fd_); }

void PreadFile::read(uint64_t offset, void* out, size_t size) const {
  uint8_t* to = static_cast<uint8_t*>(out);
  while (size > 0) {
    const ssize_t n = ::pread(fd_, to, size, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(path_ + ": " + what_ + ": " + (n < 0 ? std::strerror(errno) : "the file got shorter"));
    to += n, offset += static_cast<uint64_t>(n), size -= static_cast<size_t>(n);
  }
}

const uint8_t* PreadFile::window(uint64_t offset, size_t size) {
  if (offset < window_at_ || offset - window_at_ > window_.size() || size > window_.size() - (offset - window_at_)) {
    window_.resize(static_cast<size_t>(std::min<uint64_t>(std::max(size, kWindow), size_ - offset)));
    read(offset, window_.data(), window_.size());
    window_at_ = offset;
  }
  return window_.data() + (offset - window_at_);
}

}  // namespace viper::dataset::detail
