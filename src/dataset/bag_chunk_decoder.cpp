#include "bag_chunk_decoder.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <xxhash.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <new>

namespace viper::dataset::detail {

namespace {

constexpr size_t kMaxLz4Block = 4u << 20;  // LZ4F_max4MB, the largest block size of a frame

std::string sizes(size_t got, size_t want) {
  return "decompresses to " + std::to_string(got) + " bytes, its header says " + std::to_string(want);
}

}  // namespace

BagChunkDecoder::BagChunkDecoder() {
  if (LZ4F_isError(LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION))) throw std::bad_alloc();
}

BagChunkDecoder::~BagChunkDecoder() { LZ4F_freeDecompressionContext(lz4_); }

std::string BagChunkDecoder::decode(BagCompression compression, const uint8_t* in, size_t in_size, ChunkBytes& out,
                                    size_t size) {
  if (compression == BagCompression::kLz4) return decodeLz4(in, in_size, out, size);
  if (compression == BagCompression::kBz2) return decodeBz2(in, in_size, out, size);
  return "not a compressed chunk";
}

// Streamed into `out` as it grows, rather than BZ2_bzBuffToBuffDecompress into `size` bytes at
// once: a damaged header's size (up to 4 GB) is then never allocated unless the data make it.
std::string BagChunkDecoder::decodeBz2(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size) {
  constexpr size_t kMaxPiece = std::numeric_limits<unsigned int>::max();
  if (in_size > kMaxPiece) return "larger than bzip2 takes";
  bz_stream stream{};
  if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) throw std::bad_alloc();
  stream.next_in = const_cast<char*>(reinterpret_cast<const char*>(in));
  stream.avail_in = static_cast<unsigned int>(in_size);
  out.resize(std::min(size + 1, std::max<size_t>(8 * in_size, 1u << 20)));  // + 1: to see more than `size`
  size_t written = 0;
  std::string problem;
  for (;;) {
    if (written == out.size()) {
      if (out.size() > size) {
        problem = "decompresses to more bytes than its header says (" + std::to_string(size) + ")";
        break;
      }
      out.resize(std::min(size + 1, 2 * out.size()));
    }
    stream.next_out = reinterpret_cast<char*>(out.data() + written);
    stream.avail_out = static_cast<unsigned int>(std::min(out.size() - written, kMaxPiece));
    const unsigned int in_left = stream.avail_in, out_left = stream.avail_out;
    const int rc = BZ2_bzDecompress(&stream);
    written += out_left - stream.avail_out;
    if (rc == BZ_STREAM_END) {
      if (written != size) problem = sizes(written, size);
      else if (stream.avail_in != 0) problem = std::to_string(stream.avail_in) + " bytes after the bzip2 stream";
      break;
    }
    if (rc != BZ_OK) problem = "bzip2 error " + std::to_string(rc);
    else if (stream.avail_in == in_left && stream.avail_out == out_left)
      problem = "the bzip2 stream is cut off after " + std::to_string(in_size) + " bytes";
    if (!problem.empty()) break;
  }
  BZ2_bzDecompressEnd(&stream);
  return problem;
}

std::string BagChunkDecoder::decodeLz4(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size) {
  // liblz4 decodes a block straight into `out` only where a whole block (up to 4 MiB) fits there,
  // else into a buffer of its own and copies it (1 ms of a 1080p raw frame's 16 ms of reading):
  // room for one more block behind the chunk.
  out.resize(size + kMaxLz4Block);
  LZ4F_resetDecompressionContext(lz4_);
  // The frame's header says which checksums follow. liblz4's own XXH32 (Debian's build: vectorised
  // without a 32-bit multiply) takes 2.3 times as long as libxxhash's, so a content checksum is
  // checked here, over the whole chunk at once, with libxxhash: the same XXH32, the same verdict.
  // Frames with block checksums are left to liblz4, which checks both.
  LZ4F_frameInfo_t info{};
  size_t read = in_size;
  const size_t header = LZ4F_getFrameInfo(lz4_, &info, in, &read);
  if (LZ4F_isError(header)) return std::string("LZ4: ") + LZ4F_getErrorName(header);
  const bool own_checksum =
      info.contentChecksumFlag == LZ4F_contentChecksumEnabled && info.blockChecksumFlag == LZ4F_noBlockChecksum;
  LZ4F_decompressOptions_t options{};
  options.stableDst = 1;  // `out` holds the whole chunk
  options.skipChecksums = own_checksum ? 1 : 0;
  size_t written = 0;
  for (;;) {
    size_t in_n = in_size - read, out_n = out.size() - written;
    const size_t rc = LZ4F_decompress(lz4_, out.data() + written, &out_n, in + read, &in_n, &options);
    if (LZ4F_isError(rc)) return std::string("LZ4: ") + LZ4F_getErrorName(rc);
    read += in_n, written += out_n;
    if (rc == 0) break;  // the frame is complete (and, unless checked below, its checksum matched)
    if (in_n == 0 && out_n == 0) {
      if (read == in_size) return "the LZ4 frame is cut off after " + std::to_string(in_size) + " bytes";
      return "decompresses to more bytes than its header says (" + std::to_string(size) + ")";
    }
  }
  if (written != size) return sizes(written, size);
  if (read != in_size) return std::to_string(in_size - read) + " bytes after the LZ4 frame";
  if (own_checksum) {
    // The frame ends with the content checksum, little endian (LZ4's frame format).
    const uint8_t* c = in + read - 4;
    const uint32_t stored = c[0] | uint32_t(c[1]) << 8 | uint32_t(c[2]) << 16 | uint32_t(c[3]) << 24;
    if (XXH32(out.data(), size, 0) != stored) return "LZ4: ERROR_contentChecksum_invalid";
  }
  return "";
}

}  // namespace viper::dataset::detail
