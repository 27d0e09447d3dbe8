// A bag chunk's data decompressed into the size its header gives. LZ4 chunks are LZ4 frames (roslz4
// writes standard ones: independent blocks, a content checksum), read with liblz4's frame API; the
// content checksum (XXH32 over every decompressed byte) is checked with libxxhash's XXH32, 2.3 times
// as fast as liblz4's own (frames with block checksums are left to liblz4, which checks both); bz2
// chunks through libbz2.
#pragma once

#include "viper/dataset/bag_file_writer.h"

#include <cstddef>
#include <cstdint>
#include <string>

struct LZ4F_dctx_s;

namespace viper::dataset::detail {

class BagChunkDecoder {
 public:
  BagChunkDecoder();
  ~BagChunkDecoder();
  BagChunkDecoder(const BagChunkDecoder&) = delete;
  BagChunkDecoder& operator=(const BagChunkDecoder&) = delete;

  /// Decompresses `in` (LZ4 or bz2) into `out`, which must come out `size` bytes long (it is
  /// resized to hold them, and may be left longer); returns "" or what is wrong (a bad frame or
  /// checksum, more or fewer bytes than `size`, bytes after the frame).
  std::string decode(BagCompression compression, const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size);

 private:
  std::string decodeLz4(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size);
  std::string decodeBz2(const uint8_t* in, size_t in_size, ChunkBytes& out, size_t size);

  LZ4F_dctx_s* lz4_ = nullptr;  // kept: it holds a block's worth of buffers
};

}  // namespace viper::dataset::detail
