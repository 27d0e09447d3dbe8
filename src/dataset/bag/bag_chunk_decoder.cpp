#include "bag_chunk_decoder.h"

#include <bzlib.h>
#include <lz4.h>
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

std::string moreThan(size_t size) {
  return "decompresses to more bytes than its header says (" + std::to_string(size) + ")";
}

std::string cutOff(size_t in_size) { return "the LZ4 frame is cut off after " + std::to_string(in_size) + " bytes"; }

uint32_t load32(const uint8_t* p) { return p[0] | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

}  // namespace

BagChunkDecoder::BagChunkDecoder() {
  if (LZ4F_isError(LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION))) throw std::bad_alloc();
  xxh_ = XXH32_createState();
  if (!xxh_) {
    LZ4F_freeDecompressionContext(lz4_);
    throw std::bad_alloc();
  }
}

BagChunkDecoder::~BagChunkDecoder() {
  LZ4F_freeDecompressionContext(lz4_);
  XXH32_freeState(xxh_);
}

std::string BagChunkDecoder::decode(BagCompression compression, const uint8_t* in, size_t in_size, ChunkBytes& out,
                                    size_t size, ChunkRouter* router, DeferredChecksum* deferred) {
  if (deferred) *deferred = DeferredChecksum();
  if (compression == BagCompression::kLz4) return decodeLz4(in, in_size, out, size, router, deferred);
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

std::string BagChunkDecoder::decodeLz4(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size,
                                       ChunkRouter* router, DeferredChecksum* deferred) {
  std::string problem;
  if (decodeLz4Blocks(in, in_size, out, size, router, deferred, problem)) return problem;
  return decodeLz4Frame(in, in_size, out, size);
}

// The frame format: https://github.com/lz4/lz4/blob/dev/doc/lz4_Frame_format.md. Blocks are
// independent, so each decompresses alone, to wherever its bytes belong.
bool BagChunkDecoder::decodeLz4Blocks(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size,
                                      ChunkRouter* router, DeferredChecksum* deferred, std::string& problem) {
  if (in_size < 7 || load32(in) != 0x184D2204u) return false;
  const uint8_t flags = in[4], block = in[5];
  const bool version_1 = (flags >> 6) == 1, independent = flags & 0x20, block_checksums = flags & 0x10,
             content_size = flags & 0x08, content_checksum = flags & 0x04, dictionary = flags & 0x01;
  const int block_id = (block >> 4) & 7;
  // Anything else (and reserved bits set) is liblz4's to judge and name.
  if (!version_1 || !independent || block_checksums || dictionary || (flags & 0x02) || (block & 0x8F) || block_id < 4)
    return false;
  const size_t max_block = size_t{1} << (8 + 2 * block_id);  // 64 KiB .. 4 MiB
  size_t at = 6 + (content_size ? 8 : 0);
  if (in_size <= at || ((XXH32(in + 4, at - 4, 0) >> 8) & 0xFF) != in[at]) return false;
  ++at;
  out.resize(size);
  XXH32_reset(xxh_, 0);
  // The routed range, once the router has placed it.
  ChunkRouter::Answer answer = router ? ChunkRouter::kNotYet : ChunkRouter::kNever;
  size_t begin = 0, end = 0;
  uint8_t* to = nullptr;
  // The content checksum: here, block by block, or by the caller (deferred) over these pieces.
  const bool defer = deferred && content_checksum;
  std::vector<BytePiece>* pieces = defer ? &deferred->pieces : nullptr;
  // Bytes [from, from + n) of the chunk, decompressed at `where`: hashed (or listed), and their part
  // of the routed range copied there unless they are there already.
  auto decoded = [&](size_t from, size_t n, const uint8_t* where) {
    if (!pieces) XXH32_update(xxh_, where, n);
    else if (!pieces->empty() && pieces->back().data + pieces->back().size == where) pieces->back().size += n;
    else pieces->push_back({where, n});
    if (answer != ChunkRouter::kRouted || where != out.data() + from) return;
    const size_t a = std::max(from, begin), b = std::min(from + n, end);
    if (a < b) std::memcpy(to + (a - begin), out.data() + a, b - a);
  };
  size_t written = 0;
  for (;;) {
    if (answer == ChunkRouter::kNotYet) {
      answer = router->route(out.data(), written, begin, end, to);
      if (answer == ChunkRouter::kRouted) {
        if (!(begin <= end && end <= size && to)) answer = ChunkRouter::kNever;
        else if (begin < written) std::memcpy(to, out.data() + begin, std::min(written, end) - begin);
      }
    }
    if (in_size - at < 4) {
      problem = cutOff(in_size);
      return true;
    }
    const uint32_t word = load32(in + at);
    at += 4;
    if (word == 0) break;  // the end mark
    const size_t stored = word & 0x7FFFFFFFu;
    if (stored > in_size - at) {
      problem = cutOff(in_size);
      return true;
    }
    const char* src = reinterpret_cast<const char*>(in + at);
    const size_t room = std::min(size - written, max_block);
    // Straight into the routed range where the block starts inside it (it must end there too).
    uint8_t* direct = answer == ChunkRouter::kRouted && written >= begin && written < end ? to + (written - begin) : nullptr;
    const size_t direct_room = direct ? std::min(end - written, max_block) : 0;
    size_t n = 0;
    if (word >> 31) {  // stored as it is
      if (stored > max_block) {
        problem = "LZ4: ERROR_maxBlockSize_invalid";
        return true;
      }
      if (stored > size - written) {
        problem = moreThan(size);
        return true;
      }
      n = stored;
      uint8_t* where = direct && n <= direct_room ? direct : out.data() + written;
      std::memcpy(where, src, n);
      decoded(written, n, where);
    } else {
      const int got = direct ? LZ4_decompress_safe(src, reinterpret_cast<char*>(direct), static_cast<int>(stored),
                                                   static_cast<int>(direct_room))
                             : -1;
      if (got >= 0) {
        n = static_cast<size_t>(got);
        decoded(written, n, direct);
      } else {
        uint8_t* where = out.data() + written;
        const int here =
            LZ4_decompress_safe(src, reinterpret_cast<char*>(where), static_cast<int>(stored), static_cast<int>(room));
        if (here < 0) {
          // Past the chunk's end, or damaged: a block's worth of room tells which.
          spare_.resize(max_block);
          const bool whole = room < max_block && LZ4_decompress_safe(src, reinterpret_cast<char*>(spare_.data()),
                                                                     static_cast<int>(stored),
                                                                     static_cast<int>(max_block)) >= 0;
          problem = whole ? moreThan(size) : "LZ4: ERROR_decompressionFailed";
          return true;
        }
        n = static_cast<size_t>(here);
        decoded(written, n, where);
      }
    }
    written += n;
    at += stored;
  }
  uint32_t checksum = 0;
  if (content_checksum) {
    if (in_size - at < 4) {
      problem = cutOff(in_size);
      return true;
    }
    checksum = load32(in + at);
    at += 4;
  }
  if (written != size) problem = sizes(written, size);
  else if (at != in_size) problem = std::to_string(in_size - at) + " bytes after the LZ4 frame";
  else if (defer) deferred->pending = true, deferred->expected = checksum;
  else if (content_checksum && XXH32_digest(xxh_) != checksum) problem = kLz4ChecksumProblem;
  return true;
}

std::string BagChunkDecoder::decodeLz4Frame(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size) {
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
    if (XXH32(out.data(), size, 0) != load32(in + read - 4)) return kLz4ChecksumProblem;
  }
  return "";
}

}  // namespace viper::dataset::detail
