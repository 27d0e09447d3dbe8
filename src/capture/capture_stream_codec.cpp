// PartCodec: a frame payload's parts as zstd frames (found by their own frame and block headers) or
// as LZ4 blocks behind an 8-byte size header (LZ4's block format has none).
#include "capture_stream_codec.h"

#include <lz4.h>

#include <stdexcept>
#include <string>

namespace viper {

const char* captureCodecName(CaptureCodec codec) {
  switch (codec) {
    case CaptureCodec::kZstd: return "zstd";
    case CaptureCodec::kLz4: return "lz4";
  }
  return "unknown";
}

bool parseCaptureCodec(const std::string& name, CaptureCodec& codec) {
  if (name == "zstd") codec = CaptureCodec::kZstd;
  else if (name == "lz4") codec = CaptureCodec::kLz4;
  else return false;
  return true;
}

namespace capture_format {
namespace {

std::string partName(CaptureCodec codec, int k, int count) {
  return std::string(codec == CaptureCodec::kLz4 ? "lz4 part " : "zstd frame ") + std::to_string(k + 1) + " of " +
         std::to_string(count) + ": ";
}

}  // namespace

PartCodec::PartCodec(CaptureCodec codec, int zstd_level) : codec_(codec), level_(zstd_level) {
  if (codec != CaptureCodec::kZstd && codec != CaptureCodec::kLz4)
    throw std::runtime_error("unknown capture codec " + std::to_string(static_cast<uint32_t>(codec)));
}

PartCodec::~PartCodec() {
  ZSTD_freeCCtx(cctx_);
  ZSTD_freeDCtx(dctx_);
}

size_t PartCodec::bound(const Piece* pieces, int count) const {
  size_t n = 0;
  for (int k = 0; k < count; ++k)
    n += codec_ == CaptureCodec::kLz4
             ? kLz4PartHeaderSize + static_cast<size_t>(LZ4_compressBound(static_cast<int>(pieces[k].size)))
             : ZSTD_compressBound(pieces[k].size);
  return n;
}

size_t PartCodec::compress(const Piece* pieces, int count, char* dst, size_t capacity) {
  size_t out = 0;
  for (int k = 0; k < count; ++k) {
    const char* src = static_cast<const char*>(pieces[k].data);
    const size_t part = pieces[k].size;
    if (codec_ == CaptureCodec::kLz4) {
      // Parts are at most kMaxRawPayloadBytes (1 GiB), which LZ4's int sizes hold.
      const int n = LZ4_compress_default(src, dst + out + kLz4PartHeaderSize, static_cast<int>(part),
                                         static_cast<int>(capacity - out - kLz4PartHeaderSize));
      if (n <= 0 && part > 0) throw std::runtime_error("lz4 compression failed");
      putU32(dst + out, static_cast<uint32_t>(n));
      putU32(dst + out + 4, static_cast<uint32_t>(part));
      out += kLz4PartHeaderSize + static_cast<size_t>(n);
    } else {
      if (!cctx_ && !(cctx_ = ZSTD_createCCtx())) throw std::runtime_error("cannot create zstd context");
      const size_t n = ZSTD_compressCCtx(cctx_, dst + out, capacity - out, src, part, level_);
      if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
      out += n;
    }
  }
  return out;
}

uint64_t PartCodec::maxCompressed() const {
  if (codec_ == CaptureCodec::kLz4)
    return kMaxParts * (kLz4PartHeaderSize + static_cast<uint64_t>(LZ4_compressBound(static_cast<int>(kMaxRawPayloadBytes))));
  return ZSTD_compressBound(kMaxRawPayloadBytes);
}

// A zstd frame's extent comes from its frame and block headers (ZSTD_findFrameCompressedSize
// decompresses nothing), an LZ4 part's from its size header; every size is checked against what the
// chunk holds before anything is allocated or decompressed.
void PartCodec::find(const char* src, size_t csize, uint64_t rsize, CompressedPart* parts, int count) const {
  size_t at = 0;
  uint64_t total = 0;
  for (int k = 0; k < count; ++k) {
    const std::string part = partName(codec_, k, count);
    if (at == csize) throw std::runtime_error(part + "missing");
    size_t n;
    uint64_t c;
    if (codec_ == CaptureCodec::kLz4) {
      if (csize - at < kLz4PartHeaderSize)
        throw std::runtime_error(part + "size header cut short (" + std::to_string(csize - at) + " bytes)");
      const uint64_t block = getU32(src + at);
      c = getU32(src + at + 4);
      if (c > kMaxRawPayloadBytes || block > static_cast<uint64_t>(LZ4_compressBound(static_cast<int>(c))))
        throw std::runtime_error(part + "sizes out of range (compressed " + std::to_string(block) + ", raw " +
                                 std::to_string(c) + ")");
      if (block > csize - at - kLz4PartHeaderSize)
        throw std::runtime_error(part + "declares " + std::to_string(block) + " compressed bytes, " +
                                 std::to_string(csize - at - kLz4PartHeaderSize) + " remain");
      n = kLz4PartHeaderSize + block;
    } else {
      n = ZSTD_findFrameCompressedSize(src + at, csize - at);
      if (ZSTD_isError(n)) throw std::runtime_error(part + ZSTD_getErrorName(n));
      const unsigned long long content = ZSTD_getFrameContentSize(src + at, n);
      if (content >= ZSTD_CONTENTSIZE_ERROR) throw std::runtime_error(part + "declares no valid size");
      c = content;
    }
    if (c > rsize - total)
      throw std::runtime_error(part + "declares " + std::to_string(c) + " bytes, more than the chunk header's " +
                               std::to_string(rsize) + " in all");
    parts[k].begin = at, parts[k].size = n, parts[k].content = c;
    at += n;
    total += c;
  }
  const char* kind = codec_ == CaptureCodec::kLz4 ? "lz4 parts" : "zstd frames";
  if (at != csize)
    throw std::runtime_error(std::to_string(csize - at) + " bytes after the payload's " + kind);
  if (total != rsize)
    throw std::runtime_error(std::string(kind) + " declare " + std::to_string(total) + " bytes, chunk header says " +
                             std::to_string(rsize));
}

void PartCodec::decompress(const char* src, size_t size, char* dst, size_t content) {
  size_t got;
  if (codec_ == CaptureCodec::kLz4) {
    // The part's header already stands for its block: decompress the block behind it. The safe
    // decoder never writes past `content` bytes nor reads past `size`, whatever the block holds.
    const int n = LZ4_decompress_safe(src + kLz4PartHeaderSize, dst, static_cast<int>(size - kLz4PartHeaderSize),
                                      static_cast<int>(content));
    if (n < 0) throw std::runtime_error("lz4 decompression failed (malformed block)");
    got = static_cast<size_t>(n);
  } else {
    if (!dctx_ && !(dctx_ = ZSTD_createDCtx())) throw std::runtime_error("cannot create zstd context");
    got = ZSTD_decompressDCtx(dctx_, dst, content, src, size);
    if (ZSTD_isError(got)) throw std::runtime_error(std::string("zstd decompression failed: ") + ZSTD_getErrorName(got));
  }
  if (got != content)
    throw std::runtime_error("decompressed to " + std::to_string(got) + " bytes, expected " + std::to_string(content));
}

}  // namespace capture_format
}  // namespace viper
