// SHA-256 of files taken from their bytes while they are written, so that a generated sequence's
// done-marker (sequence_marker.h) need not read them back: the layout's writers hash the bytes they
// hold anyway and record the checksum here; the marker takes it for every file that still has the
// size recorded and reads only the rest (the ground-truth bag, whose header is rewritten at close
// and comes first in the hash). docs/dataset_generation.md#finished-unfinished-redone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>

struct evp_md_ctx_st;

namespace viper::dataset {

/// A SHA-256 fed piece by piece (OpenSSL).
class Sha256 {
 public:
  /// Throws std::runtime_error if OpenSSL cannot start one.
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;

  void update(const void* bytes, size_t size);
  /// The digest of everything fed so far as 64 lowercase hex digits; the hash then starts over.
  std::string hex();

 private:
  std::unique_ptr<evp_md_ctx_st, void (*)(evp_md_ctx_st*)> ctx_;
};

/// SHA-256 of `size` bytes as 64 lowercase hex digits.
std::string sha256Hex(const void* bytes, size_t size);

/// Checksums of files as their writers computed them. Thread-safe: writer threads record, the
/// marker looks up.
class FileDigests {
 public:
  /// Records the SHA-256 and size of the file at `path` as just written. A path recorded twice is
  /// forgotten: which of two writes came last is unknown here, so that file is read back.
  void record(const std::filesystem::path& path, uint64_t size, const std::string& sha256);
  /// The checksum recorded for `path` if the file on disk still has the recorded size; "" otherwise
  /// (nothing recorded, recorded twice, or changed since): then the caller reads the file.
  std::string find(const std::filesystem::path& path, uint64_t size_on_disk) const;
  /// Files with a checksum.
  size_t size() const;

 private:
  struct Entry {
    uint64_t size = 0;
    std::string sha256;  // "" once recorded twice
  };
  mutable std::mutex mutex_;
  std::map<std::string, Entry> files_;  // by lexically normal path
};

}  // namespace viper::dataset
