#include "bag_chunk_decoder.h"

#include <bzlib.h>
#include <lz4frame.h>

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
  if (compression != BagCompression::kBz2) return "not a compressed chunk";
  if (in_size > std::numeric_limits<unsigned int>::max() || size > std::numeric_limits<unsigned int>::max())
    return "larger than bzip2 takes";
  out.resize(size);
  unsigned int n = static_cast<unsigned int>(size);
  const int rc = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out.data()), &n,
                                            const_cast<char*>(reinterpret_cast<const char*>(in)),
                                            static_cast<unsigned int>(in_size), 0, 0);
  if (rc == BZ_OUTBUFF_FULL) return "decompresses to more bytes than its header says (" + std::to_string(size) + ")";
  if (rc != BZ_OK) return "bzip2 error " + std::to_string(rc);
  if (n != size) return sizes(n, size);
  return "";
}

std::string BagChunkDecoder::decodeLz4(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size) {
  // liblz4 decodes a block straight into `out` only where a whole block (up to 4 MiB) fits there,
  // else into a buffer of its own and copies it (1 ms of a 1080p raw frame's 16 ms of reading):
  // room for one more block behind the chunk.
  out.resize(size + kMaxLz4Block);
  LZ4F_resetDecompressionContext(lz4_);
  LZ4F_decompressOptions_t options{};
  options.stableDst = 1;  // `out` holds the whole chunk
  size_t read = 0, written = 0;
  for (;;) {
    size_t in_n = in_size - read, out_n = out.size() - written;
    const size_t rc = LZ4F_decompress(lz4_, out.data() + written, &out_n, in + read, &in_n, &options);
    if (LZ4F_isError(rc)) return std::string("LZ4: ") + LZ4F_getErrorName(rc);
    read += in_n, written += out_n;
    if (rc == 0) break;  // the frame is complete and its checksum matched
    if (in_n == 0 && out_n == 0) {
      if (read == in_size) return "the LZ4 frame is cut off after " + std::to_string(in_size) + " bytes";
      return "decompresses to more bytes than its header says (" + std::to_string(size) + ")";
    }
  }
  if (written != size) return sizes(written, size);
  if (read != in_size) return std::to_string(in_size - read) + " bytes after the LZ4 frame";
  return "";
}

}  // namespace viper::dataset::detail
