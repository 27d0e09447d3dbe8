// The done-marker of a generated sequence: its frame count and the SHA-256 of every file, in
// sha256sum's format (so `sha256sum -c` checks it too). A sequence counts as finished only when its
// marker exists and every file still has its checksum; anything else is redone.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace viper::dataset {

/// SHA-256 of a file as 64 lowercase hex digits. Throws std::runtime_error naming the file if it
/// cannot be read.
std::string sha256OfFile(const std::filesystem::path& path);

/// One file of a sequence: its path relative to the dataset root and its checksum.
struct MarkedFile {
  std::string relative_path;
  std::string sha256;
};

/// What a marker holds.
struct SequenceMarker {
  uint64_t frames = 0;
  std::vector<MarkedFile> files;
};

/// Writes `marker` to `path` atomically (a temporary file renamed into place). Lines: "# frames N"
/// then "<sha256>  <relative path>" per file. Throws std::runtime_error naming the path on failure.
void writeSequenceMarker(const std::filesystem::path& path, const SequenceMarker& marker);
/// Reads a marker. Throws std::runtime_error naming the file and line if it is malformed.
SequenceMarker readSequenceMarker(const std::filesystem::path& path);
/// Checks every file of the marker under `root`: "" if all are there with their checksums, else
/// the first that is missing or differs.
std::string verifySequence(const std::filesystem::path& root, const SequenceMarker& marker);

}  // namespace viper::dataset
