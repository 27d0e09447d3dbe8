// The capture stream (.vcap): a versioned sequence of checksummed, compressed (zstd or LZ4) frame chunks.
// The byte layout is documented in docs/capture_format.md.
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace viper {

/// Stream format version CaptureWriter writes, whatever the codec (5: each of a payload's four images
/// compressed on its own, so that a reader decompresses it straight where it is used, or skips it;
/// the codec named in the file header). Builds that read only versions 1 to 4 reject it by its version.
constexpr uint32_t kCaptureFormatVersion = 5;
/// Newest format version CaptureReader reads.
constexpr uint32_t kNewestReadableCaptureFormatVersion = 5;
/// Oldest format version CaptureReader still reads (version 1 frames have no gaps; versions 1 and 2
/// compress a payload as one zstd frame).
constexpr uint32_t kOldestReadableCaptureFormatVersion = 1;

/// How a stream's frame payloads are compressed (the file header's codec field from version 4).
enum class CaptureCodec : uint32_t {
  kZstd = 1,  ///< zstd frames at the writer's level: files about half the size, for captures kept long
  kLz4 = 2,   ///< LZ4 blocks (the default): twice the size, half the CPU to write and to read
              ///< (docs/capture_layer.md: a 1080p frame in 9.7 ms against 17.5, read in 5.2 against 9.2)
};
/// "zstd" or "lz4".
const char* captureCodecName(CaptureCodec codec);
/// Parses "zstd" or "lz4"; false for anything else.
bool parseCaptureCodec(const std::string& name, CaptureCodec& codec);

/// Thrown for any unreadable part of a stream. what() names the file, the frame number (if known)
/// and the byte offset of the damaged chunk: "<file>: offset <offset>: <what>".
class CaptureFormatError : public std::runtime_error {
 public:
  CaptureFormatError(const std::string& file, uint64_t offset, const std::string& what);
  /// Path (or name) of the stream.
  const std::string& file() const { return file_; }
  /// Byte offset of the damaged chunk (0 for the file header).
  uint64_t offset() const { return offset_; }

 private:
  std::string file_;
  uint64_t offset_;
};

/// The stream header: format version and free-form metadata about who wrote it.
struct CaptureHeader {
  /// Format version read from the file; the writer ignores it and writes kCaptureFormatVersion.
  uint32_t version = kCaptureFormatVersion;
  /// How the payloads are compressed: the writer compresses with it, the reader reports what it read
  /// (zstd for versions 1 to 3, which have no codec field).
  CaptureCodec codec = CaptureCodec::kLz4;
  /// Name of the captured program and the capture profile used (informational).
  std::string program;
  std::string profile;
};

/// Serialises one frame to the uncompressed chunk payload bytes, and back.
std::string encodeFramePayload(const CaptureFrame& frame);
/// Same, into `out` (replacing its contents; reusing its capacity between frames).
void encodeFramePayload(const CaptureFrame& frame, std::string& out);
/// Throws std::runtime_error with a description if the payload is malformed.
CaptureFrame decodeFramePayload(const std::string& payload);
/// Same, from `size` bytes at `data` into `frame` (reusing the capacity of its vectors).
/// Bounds-checked: never reads outside [data, data + size) and never allocates more than the
/// payload can hold. Throws std::runtime_error naming the field and byte position on bad input.
void decodeFramePayload(const char* data, size_t size, CaptureFrame& frame,
                        uint32_t version = kCaptureFormatVersion);

/// Turns frames into finished chunks (payload, compression, checksums) away from any file, so
/// that several encoders can work in parallel while one CaptureWriter appends their chunks in
/// order (writeEncoded). Not thread-safe itself: one per thread.
class CaptureChunkEncoder {
 public:
  /// Throws std::runtime_error if `codec` is unknown or its contexts cannot be created.
  explicit CaptureChunkEncoder(CaptureCodec codec, int zstd_level = 1);
  ~CaptureChunkEncoder();
  CaptureChunkEncoder(const CaptureChunkEncoder&) = delete;
  CaptureChunkEncoder& operator=(const CaptureChunkEncoder&) = delete;

  /// Encodes `frame` into this encoder's chunk (valid until the next call). Throws
  /// std::runtime_error naming `stream` and the frame if the payload exceeds 1 GiB or
  /// compression fails.
  void encode(const CaptureFrame& frame, const std::string& stream);
  /// The chunk: header and compressed payload, as they go into the file.
  const char* data() const;
  size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes a stream. Each frame is flushed as one whole chunk so a follower never sees a frame
/// without its checksum. Not thread-safe.
class CaptureWriter {
 public:
  /// Opens (truncates) `path`, compressing with `header.codec`. Throws std::runtime_error if it
  /// cannot be opened. `zstd_level` (zstd only) 1 is fast; higher compresses more; negative levels
  /// are zstd's faster ones (larger files).
  CaptureWriter(const std::string& path, const CaptureHeader& header, int zstd_level = 1);
  ~CaptureWriter();  ///< Writes the end marker if close() was not called.
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  /// Appends `frame` as one chunk (one fwrite of header and payload, then fflush).
  /// Throws std::runtime_error if the stream is closed, the frame is too large (payload over
  /// 1 GiB), compression fails or the file cannot be written.
  void write(const CaptureFrame& frame);
  /// Appends a chunk encoded by `chunk` (with this stream's codec), like write() does.
  void writeEncoded(const CaptureChunkEncoder& chunk);
  /// Writes the end-of-stream marker and closes the file. Idempotent.
  void close();
  /// Bytes written so far, file header included.
  uint64_t bytesWritten() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The four images of a frame, in the order of its payload.
enum class CaptureImage : int { kColor = 0, kDepth = 1, kDrawIds = 2, kPrimitiveIds = 3 };

/// Storage for a frame's images chosen by whoever uses them (a message's pixels, say). With a sink
/// set, CaptureReader::next() decompresses each image of a version 5 stream once, straight into the
/// sink's storage; from older versions it copies each image there once decoded.
class CaptureImageSink {
 public:
  virtual ~CaptureImageSink() = default;
  /// Writable storage for the `bytes` bytes of `image` of `frame` (bytes > 0), whose head (number,
  /// time_s, condition, width, height) is already decoded; nullptr keeps the image in the frame's
  /// vector. An image given storage is left empty in the frame. The reader writes exactly `bytes`
  /// bytes there, or throws (the storage then holds anything: the frame is not returned).
  virtual void* imageStorage(CaptureImage image, const CaptureFrame& frame, size_t bytes) = 0;
};

/// Reads a stream, optionally following it while another process still writes it.
class CaptureReader {
 public:
  /// Opens `path` and reads its header. Throws CaptureFormatError (bad magic, unknown version,
  /// truncated header) or std::runtime_error (cannot open).
  explicit CaptureReader(const std::string& path);
  /// Reads from an already open stdio stream (e.g. from fmemopen), which the reader takes over
  /// and closes. `name` stands for the file in error messages. Throws like the path constructor.
  CaptureReader(std::FILE* file, const std::string& name);
  ~CaptureReader();
  CaptureReader(const CaptureReader&) = delete;
  CaptureReader& operator=(const CaptureReader&) = delete;

  /// The stream's header as read by the constructor.
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
  /// Like next(), but leaves the four images of `frame` empty (color_rgb, depth_window, draw_ids,
  /// primitive_ids): for readers that need only the draws and meshes. From version 3 the images'
  /// bytes (zstd or LZ4) are checksummed but not decompressed (most of a frame's cost); from older
  /// versions the whole payload is decompressed. Damage is reported exactly as by next().
  Status nextWithoutImages(CaptureFrame& frame, bool follow = false);

  /// Where next() puts the images of the frames it reads (nullptr, the default: the frame's vectors).
  /// The sink must outlive the reads; nextWithoutImages() never calls it.
  void setImageSink(CaptureImageSink* sink);

  /// Byte offset of the next chunk to read.
  uint64_t offset() const;
  /// The path (or name) given to the constructor.
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace viper
