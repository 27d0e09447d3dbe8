// The compression of a frame payload's three parts (head, images, rest) by the stream's codec, for
// the writer and the reader (see docs/capture_format.md#chunk). Private to the capture stream.
#pragma once

#include "capture_stream_format.h"
#include "viper/capture/capture_stream.h"

#include <zstd.h>

#include <cstddef>
#include <cstdint>

namespace viper {
namespace capture_format {

/// An LZ4 part is an 8-byte header, compressed size u32 and decompressed size u32, then one LZ4 block
/// (LZ4_compress_default) of that many bytes. LZ4's block format has no headers of its own, so the
/// sizes are what lets a reader step over the images without decompressing them; both fit a u32
/// because a payload is at most 1 GiB.
constexpr size_t kLz4PartHeaderSize = 8;

/// Where one compressed part lies in a chunk's payload (`begin`, `size` bytes) and its decompressed size.
struct CompressedPart {
  size_t begin = 0;
  size_t size = 0;
  uint64_t content = 0;
};

/// Bytes to compress as one part.
struct Piece {
  const void* data = nullptr;
  size_t size = 0;
};

/// One codec's compression of payload parts, with its reusable contexts. Errors are
/// std::runtime_error whose message the writer and reader put behind the file and frame.
class PartCodec {
 public:
  /// Throws std::runtime_error if `codec` is unknown or zstd's contexts cannot be created.
  explicit PartCodec(CaptureCodec codec, int zstd_level = 1);
  ~PartCodec();
  PartCodec(const PartCodec&) = delete;
  PartCodec& operator=(const PartCodec&) = delete;

  CaptureCodec codec() const { return codec_; }

  /// Largest compressed payload of the `count` pieces.
  size_t bound(const Piece* pieces, int count) const;
  /// Compresses each of the `count` pieces as one part into `dst`, which holds at least
  /// bound(pieces, count) bytes; returns the bytes written.
  size_t compress(const Piece* pieces, int count, char* dst, size_t capacity);

  /// Largest compressed payload a chunk may declare (that of a payload of kMaxRawPayloadBytes).
  uint64_t maxCompressed() const;
  /// Finds the `count` parts of `csize` compressed bytes from their headers alone (nothing is
  /// decompressed) and checks that they fill `csize` exactly and decompress to `rsize` in all.
  /// Messages: "zstd frame K of N: ...", "lz4 part K of N: ...".
  void find(const char* src, size_t csize, uint64_t rsize, CompressedPart* parts, int count) const;
  /// Decompresses one part as find() located it (`size` bytes at `src`; for zstd also a version 1 or 2
  /// payload, one zstd frame) into exactly `content` bytes at `dst`.
  void decompress(const char* src, size_t size, char* dst, size_t content);

 private:
  CaptureCodec codec_;
  int level_;
  ZSTD_CCtx* cctx_ = nullptr;
  ZSTD_DCtx* dctx_ = nullptr;
};

}  // namespace capture_format
}  // namespace viper
