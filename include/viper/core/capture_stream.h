// The capture stream (.vcap): a versioned sequence of checksummed, zstd-compressed frame chunks.
// The byte layout is documented in docs/capture_format.md.
#pragma once

#include "viper/core/capture_frame.h"

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace viper {

/// Current stream format version written by CaptureWriter.
constexpr uint32_t kCaptureFormatVersion = 1;

/// Thrown for any unreadable part of a stream. what() names the file, the frame number (if known)
/// and the byte offset of the damaged chunk.
class CaptureFormatError : public std::runtime_error {
 public:
  CaptureFormatError(const std::string& file, uint64_t offset, const std::string& what);
  const std::string& file() const { return file_; }
  uint64_t offset() const { return offset_; }

 private:
  std::string file_;
  uint64_t offset_;
};

/// Options of the stream header: free-form metadata about who wrote it.
struct CaptureHeader {
  uint32_t version = kCaptureFormatVersion;
  /// Name of the captured program and the capture profile used (informational).
  std::string program;
  std::string profile;
};

/// Serialises one frame to the uncompressed chunk payload bytes, and back.
std::string encodeFramePayload(const CaptureFrame& frame);
/// Throws std::runtime_error with a description if the payload is malformed.
CaptureFrame decodeFramePayload(const std::string& payload);

/// Writes a stream. Each frame is flushed as one whole chunk so a follower never sees a frame
/// without its checksum. Not thread-safe.
class CaptureWriter {
 public:
  /// Opens (truncates) `path`. Throws std::runtime_error if it cannot be opened.
  /// `zstd_level` 1 is fast; higher compresses more.
  CaptureWriter(const std::string& path, const CaptureHeader& header, int zstd_level = 1);
  ~CaptureWriter();  ///< Writes the end marker if close() was not called.
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  void write(const CaptureFrame& frame);
  /// Writes the end-of-stream marker and closes the file. Idempotent.
  void close();
  uint64_t bytesWritten() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a stream, optionally following it while another process still writes it.
class CaptureReader {
 public:
  /// Opens `path` and reads its header. Throws CaptureFormatError (bad magic, unknown version,
  /// truncated header) or std::runtime_error (cannot open).
  explicit CaptureReader(const std::string& path);
  ~CaptureReader();
  CaptureReader(const CaptureReader&) = delete;
  CaptureReader& operator=(const CaptureReader&) = delete;

  const CaptureHeader& header() const;

  /// Result of one read attempt.
  enum class Status {
    kFrame,    ///< `frame` holds the next frame
    kEnd,      ///< clean end-of-stream marker reached
    kPending,  ///< (follow mode) no complete chunk yet and no end marker: try again later
  };

  /// Reads the next frame. Without `follow`, hitting the end of the file without the end marker
  /// throws CaptureFormatError ("truncated"). With `follow`, an incomplete tail returns kPending
  /// and the reader stays where it was, so a later call sees the bytes written since.
  /// A corrupted chunk (bad checksum, bad payload) throws CaptureFormatError naming the frame and
  /// offset; every frame before it was already returned intact.
  Status next(CaptureFrame& frame, bool follow = false);

  /// Byte offset of the next chunk to read.
  uint64_t offset() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viper
