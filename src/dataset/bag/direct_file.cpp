#include "direct_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

namespace viper::dataset::detail {

namespace {
constexpr size_t kAlign = 4096;             // O_DIRECT's alignment of memory, offsets and sizes
constexpr size_t kStaging = 8u << 20;       // written in 8 MiB pieces

uint8_t* alignedBuffer() {
  void* p = nullptr;
  if (posix_memalign(&p, kAlign, kStaging) != 0) throw std::bad_alloc();
  return static_cast<uint8_t*>(p);
}
}  // namespace

DirectFile::DirectFile(const std::string& path, const std::string& what)
    : path_(path), what_(what), staging_(alignedBuffer(), std::free) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_DIRECT, 0644);
  direct_ = fd_ >= 0;
  if (fd_ < 0 && errno == EINVAL) fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) fail(std::strerror(errno));
}

DirectFile::~DirectFile() {
  if (fd_ >= 0) ::close(fd_);
}

void DirectFile::append(const void* bytes, size_t size) {
  const uint8_t* in = static_cast<const uint8_t*>(bytes);
  while (size > 0) {
    const size_t n = std::min(size, kStaging - staged_);
    std::memcpy(staging_.get() + staged_, in, n);
    staged_ += n, in += n, size -= n, size_ += n;
    if (staged_ == kStaging) flushStaged(false);
  }
}

void DirectFile::flushStaged(bool last) {
  // Direct writes are whole blocks: the last one is padded with zeros, cut off by ftruncate below.
  size_t length = staged_;
  if (direct_ && last && length % kAlign != 0) {
    const size_t padded = (length + kAlign - 1) / kAlign * kAlign;
    std::memset(staging_.get() + length, 0, padded - length);
    length = padded;
  }
  size_t done = 0;
  while (done < length) {
    const ssize_t n = ::pwrite(fd_, staging_.get() + done, length - done, static_cast<off_t>(written_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(std::strerror(errno));
    if (n == 0) fail("no space written");
    done += static_cast<size_t>(n);
  }
  written_ += length;
  staged_ = 0;
}

void DirectFile::finish(uint64_t offset, const void* bytes, size_t size) {
  if (fd_ < 0) return;
  flushStaged(true);
  if (written_ != size_ && ::ftruncate(fd_, static_cast<off_t>(size_)) != 0) fail(std::strerror(errno));
  // The header rewrite is small and unaligned: through the page cache.
  if (direct_ && ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_DIRECT) != 0) fail(std::strerror(errno));
  if (offset + size > size_) fail("rewrite past the end");
  if (::pwrite(fd_, bytes, size, static_cast<off_t>(offset)) != static_cast<ssize_t>(size)) fail(std::strerror(errno));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail(std::strerror(errno));
}

void DirectFile::fail(const std::string& why) const { throw std::runtime_error(path_ + ": " + what_ + ": " + why); }

}  // namespace viper::dataset::detail
