// A file read with pread, no per-record syscalls: a chunk's bytes in one read into the caller's
// buffer, and the index's small records through a window that one read fills with many of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset::detail {

class PreadFile {
 public:
  /// Opens `path` for reading. Throws std::runtime_error "PATH: WHAT: REASON".
  PreadFile(const std::string& path, const std::string& what);
  ~PreadFile();
  PreadFile(const PreadFile&) = delete;
  PreadFile& operator=(const PreadFile&) = delete;

  uint64_t size() const { return size_; }
  /// Whether `size` bytes at `offset` lie in the file (no overflow for any values).
  bool holds(uint64_t offset, uint64_t size) const { return offset <= size_ && size <= size_ - offset; }
  /// `size` bytes at `offset` (which holds() must allow) into `out`. Throws as the constructor does.
  void read(uint64_t offset, void* out, size_t size) const;
  /// `size` bytes at `offset` (which holds() must allow), valid until the next call: from the window
  /// where it has them, else the window is refilled from `offset` on.
  const uint8_t* window(uint64_t offset, size_t size);

 private:
  std::string path_, what_;
  int fd_ = -1;
  uint64_t size_ = 0;
  std::vector<uint8_t> window_;
  uint64_t window_at_ = 0;
};

}  // namespace viper::dataset::detail
