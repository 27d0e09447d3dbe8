// Private constants and helpers of the .vcap byte layout (see docs/capture_format.md).
// Shared by the writer, the reader and the payload codec; not part of the public API.
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

namespace viper {
namespace capture_format {

// The layout is defined as little-endian IEEE 754 and written with memcpy of whole vectors.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the .vcap codec assumes a little-endian host");
static_assert(std::numeric_limits<float>::is_iec559 && std::numeric_limits<double>::is_iec559,
              "the .vcap codec assumes IEEE 754 floats");

/// File header: magic[8], version u32, fields_size u32, fields, XXH3-64 of everything before it.
constexpr char kFileMagic[8] = {'V', 'I', 'P', 'E', 'R', 'C', 'A', 'P'};
constexpr size_t kFileHeaderFixedSize = 16;
constexpr uint32_t kMaxHeaderFieldsSize = 1u << 20;

/// Chunk header (48 bytes): magic[4], type u32, frame u64, compressed u64, raw u64,
/// payload XXH3-64 u64, header XXH3-64 u64 (of the 40 bytes before it).
constexpr char kChunkMagic[4] = {'V', 'C', 'H', 'K'};
constexpr size_t kChunkHeaderSize = 48;
constexpr size_t kChunkHeaderCheckedSize = 40;
constexpr uint32_t kChunkFrame = 1;
constexpr uint32_t kChunkEnd = 2;

/// Largest uncompressed frame payload either side accepts (an 8K frame is about 0.5 GiB).
constexpr uint64_t kMaxRawPayloadBytes = 1ull << 30;
/// Largest image side the payload decoder accepts.
constexpr uint32_t kMaxImageSide = 16384;

/// Versions 3 and 4 compress a frame payload as three parts, one after the other: the head (number to
/// height), the four images (color, depth, draw ids, primitive ids) and the rest (draws, meshes). A
/// reader that wants only the draws skips the images' part without decompressing it (about 95 % of a
/// frame's bytes); the three decompressed one after the other are the payload.
constexpr int kPartsV3 = 3;
/// The images part of a version 3 or 4 frame without images: four empty vectors (a u64 count of 0 each).
constexpr size_t kEmptyImagesBytes = 4 * 8;
/// From version 5 a payload is six parts: the head (number to height, then the four images' element
/// counts), each image on its own (its bytes only), and the rest. A reader decompresses each image
/// straight into the storage it is used in (CaptureImageSink) and skips them without decompressing.
constexpr int kPartsV5 = 6;
constexpr int kMaxParts = kPartsV5;
constexpr int kImages = 4;
/// Bytes of one element of each image, in payload order (color, depth, draw ids, primitive ids).
constexpr size_t kImageElementBytes[kImages] = {1, 4, 4, 4};
/// Their names, as CaptureFrame's fields and the decoders' messages call them.
constexpr const char* kImageNames[kImages] = {"color_rgb", "depth_window", "draw_ids", "primitive_ids"};

/// The element counts of a version 5 payload's four images, in payload order.
struct ImageCounts {
  uint64_t n[kImages] = {0, 0, 0, 0};
  /// Bytes of image `k` (n[k] is at most the payload's size, so this does not overflow).
  size_t bytes(int k) const;
};
ImageCounts imageCounts(const CaptureFrame& frame);

/// A version 5 payload's head part (number to height, the image counts) and rest part (draws,
/// unrecorded draws, meshes), encoded on their own: the writer compresses them and the frame's images
/// where they are, without building the whole payload.
void encodePayloadHead(const CaptureFrame& frame, std::string& out);
void encodePayloadRest(const CaptureFrame& frame, std::string& out);
/// Bytes of `frame`'s whole version 5 payload.
size_t payloadSize(const CaptureFrame& frame);
/// Decode the head and rest parts of a version 5 payload, bounds-checked like decodeFramePayload()
/// (each part must be consumed exactly). `at` is the rest's first byte in the payload, for messages.
void decodePayloadHead(const char* data, size_t size, CaptureFrame& frame, ImageCounts& counts);
void decodePayloadRest(const char* data, size_t size, size_t at, CaptureFrame& frame, uint32_t version);

inline void putU32(char* p, uint32_t v) { std::memcpy(p, &v, 4); }
inline void putU64(char* p, uint64_t v) { std::memcpy(p, &v, 8); }
inline uint32_t getU32(const char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
inline uint64_t getU64(const char* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

/// A growable byte buffer that, unlike std::string, does not zero-fill when it grows
/// (frames are tens of MB; the bytes are overwritten right away).
class ByteBuffer {
 public:
  char* data() { return data_.get(); }
  const char* data() const { return data_.get(); }
  /// Makes room for `n` bytes; the previous contents are not kept.
  void reserveDiscard(size_t n) {
    if (n <= capacity_) return;
    data_.reset(new char[n]);
    capacity_ = n;
  }

 private:
  std::unique_ptr<char[]> data_;
  size_t capacity_ = 0;
};

}  // namespace capture_format
}  // namespace viper
