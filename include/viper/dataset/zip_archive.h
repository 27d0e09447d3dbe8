// Zip archives as far as .npz files need them: write a set of named entries, stored or deflated
// (ISA-L or libdeflate), and read entries back through libzip, stored or deflated, checking their CRCs.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viper::dataset {

class FileDigests;

/// One file inside a zip archive.
struct ZipEntry {
  std::string name;
  std::vector<uint8_t> bytes;
};

/// How writeZip stores entries.
struct ZipWriteOptions {
  /// 0: stored (as numpy.savez); 1: deflated by ISA-L's igzip at its level 1; 2..9: deflated by
  /// libdeflate at this level (numpy.savez_compressed uses zlib's level 6). On 1080p flow 1 is
  /// about 2.5 times as fast as libdeflate's level 2 and writes 1.3 times its bytes.
  int deflate_level = 1;
  /// When set, each archive's SHA-256 is recorded there as it is written (from the bytes in memory).
  FileDigests* digests = nullptr;
};

/// Writes `entries` to a new archive at `path`, replacing any file there: a temporary file beside
/// `path`, then renamed, so readers never see a half-written archive.
/// Entry times are fixed (1980-01-01) so equal inputs give equal files.
/// Throws std::invalid_argument for no entries, duplicate names or a level outside 0..9, and
/// std::runtime_error naming `path` if the archive cannot be written (e.g. missing folder).
void writeZip(const std::string& path, const std::vector<ZipEntry>& entries,
              const ZipWriteOptions& options = ZipWriteOptions());

/// Reads entries of an existing archive. Not thread-safe; one reader per thread.
class ZipReader {
 public:
  /// Opens `path` and checks the archive's consistency. Throws std::runtime_error naming `path`
  /// if it is missing, not a zip archive, truncated or inconsistent.
  explicit ZipReader(const std::string& path);
  ~ZipReader();
  ZipReader(const ZipReader&) = delete;
  ZipReader& operator=(const ZipReader&) = delete;

  const std::string& path() const { return path_; }
  /// Names of all entries, in archive order.
  std::vector<std::string> names() const;
  bool has(const std::string& name) const;
  /// The uncompressed bytes of entry `name`. Throws std::runtime_error naming the archive and
  /// the entry if it is missing, uses an unsupported compression, fails to inflate or fails
  /// its CRC check.
  std::vector<uint8_t> read(const std::string& name) const;

 private:
  std::string path_;
  struct Handle;
  std::unique_ptr<Handle> handle_;
};

}  // namespace viper::dataset
