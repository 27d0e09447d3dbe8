// A file written once, front to back, around the page cache (O_DIRECT): for outputs of tens of MB a
// frame (a ground-truth bag) that nothing reads soon. Through the page cache, the kernel copies
// every byte and allocates (and, once memory is full of cache, reclaims) pages for it: on the
// package's 2-core VM most of a ground-truth bag's writing time (bench_bag_writer: 91 MB a frame
// through the cache 218 ms of CPU, written directly 16 ms). O_DIRECT writes from an aligned
// staging buffer skip both.
// Where O_DIRECT is refused (tmpfs, some network file systems) it writes through the cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace viper::dataset::detail {

class DirectFile {
 public:
  /// Creates (truncates) `path`. Throws std::runtime_error "PATH: WHAT: REASON" on failure, with
  /// `what` naming the kind of file ("cannot write bag").
  DirectFile(const std::string& path, const std::string& what);
  ~DirectFile();
  DirectFile(const DirectFile&) = delete;
  DirectFile& operator=(const DirectFile&) = delete;

  /// Appends `size` bytes. Throws as the constructor does (a full disk: the file keeps what was
  /// written before).
  void append(const void* bytes, size_t size);
  /// Bytes appended so far.
  uint64_t size() const { return size_; }
  /// Writes what is staged, then overwrites `size` bytes at `offset` (< size()), then closes.
  void finish(uint64_t offset, const void* bytes, size_t size);
  /// Whether the file is written around the page cache.
  bool direct() const { return direct_; }

 private:
  void flushStaged(bool last);
  [[noreturn]] void fail(const std::string& why) const;

  std::string path_, what_;
  int fd_ = -1;
  bool direct_ = false;
  uint64_t size_ = 0;     // bytes appended
  uint64_t written_ = 0;  // bytes on disk (a multiple of kAlign while direct)
  std::unique_ptr<uint8_t, void (*)(void*)> staging_;
  size_t staged_ = 0;
};

}  // namespace viper::dataset::detail
