// A bag chunk's data decompressed into the size its header gives. LZ4 chunks are LZ4 frames (roslz4
// writes standard ones: independent blocks, a content checksum). Frames of independent blocks
// without block checksums (roslz4's, BagFileWriter's) are read block by block with liblz4's block
// decoder, the content checksum (XXH32 over every decompressed byte) with libxxhash, 2.3 times as
// fast as liblz4's own; and a range of the chunk (a large message's pixels) may go to storage of the
// caller's instead: each block that falls inside it is decompressed straight there. Other LZ4 frames
// are left to liblz4's frame API; bz2 chunks go through libbz2.
#pragma once

#include "viper/dataset/bag_file_writer.h"
#include "xxh32_streams.h"

#include <cstddef>
#include <cstdint>
#include <string>

struct LZ4F_dctx_s;
struct XXH32_state_s;

namespace viper::dataset::detail {

/// Asked, as an LZ4 chunk is decompressed block by block, whether a range of it goes elsewhere.
class ChunkRouter {
 public:
  enum Answer { kNotYet, kNever, kRouted };
  virtual ~ChunkRouter() = default;
  /// `chunk` holds the chunk's first `decoded` bytes. kRouted: bytes [begin, end) of the chunk
  /// (begin <= end <= the chunk's size) go to `to` (end - begin bytes) instead; those decoded
  /// already are copied there. kNotYet: ask again after the next block.
  virtual Answer route(const uint8_t* chunk, size_t decoded, size_t& begin, size_t& end, uint8_t*& to) = 0;
};

/// An LZ4 chunk's content checksum left for the caller to check (with other chunks', side by side:
/// xxh32_streams.h): the stored value and the decompressed bytes in order.
/// The problem an LZ4 chunk whose content does not match its checksum has (liblz4's name for it).
constexpr const char kLz4ChecksumProblem[] = "LZ4: ERROR_contentChecksum_invalid";

struct DeferredChecksum {
  bool pending = false;
  uint32_t expected = 0;
  std::vector<BytePiece> pieces;
};

class BagChunkDecoder {
 public:
  BagChunkDecoder();
  ~BagChunkDecoder();
  BagChunkDecoder(const BagChunkDecoder&) = delete;
  BagChunkDecoder& operator=(const BagChunkDecoder&) = delete;

  /// Decompresses `in` (LZ4 or bz2) into `out`, which must come out `size` bytes long (it is
  /// resized to hold them, and may be left longer); returns "" or what is wrong (a bad frame or
  /// checksum, more or fewer bytes than `size`, bytes after the frame).
  /// With a router, a range of an LZ4 chunk may go elsewhere (ChunkRouter): `out` then holds the
  /// rest, and the range's place in it is left as it was.
  /// With `deferred`, an LZ4 frame's content checksum may be left to the caller (deferred->pending).
  std::string decode(BagCompression compression, const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size,
                     ChunkRouter* router = nullptr, DeferredChecksum* deferred = nullptr);

 private:
  std::string decodeLz4(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size, ChunkRouter* router,
                        DeferredChecksum* deferred);
  // An LZ4 frame of independent blocks without block checksums or dictionary, block by block;
  // false (nothing done) for other frames.
  bool decodeLz4Blocks(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size, ChunkRouter* router,
                       DeferredChecksum* deferred, std::string& problem);
  std::string decodeLz4Frame(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size);
  std::string decodeBz2(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size);

  LZ4F_dctx_s* lz4_ = nullptr;  // kept: it holds a block's worth of buffers
  XXH32_state_s* xxh_ = nullptr;
  ChunkBytes spare_;  // a block that decompresses past the chunk's end, to say so
};

}  // namespace viper::dataset::detail
