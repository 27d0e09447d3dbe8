// Frame payload codec: explicit little-endian fields, whole vectors copied with memcpy.
#include "viper/capture/capture_stream.h"

#include "capture_stream_format.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace viper {
namespace {

using capture_format::kMaxImageSide;

// Fixed bytes of one encoded DrawRecord, excluding its two variable-length arrays' contents.
constexpr size_t kDrawFixedSize = 4 + 8 * 4 + 4 + 1 + 3 * 64 + 3 * 4 + 8 + 1;
constexpr size_t kDrawFixedSizeV1 = kDrawFixedSize - 1;  // without gaps
constexpr size_t kMeshFixedSize = 8 + 8 + 8;

// From version 5 the head ends with the four images' element counts.
size_t headSize(const CaptureFrame& f) { return 8 + 8 + 4 + f.condition.size() + 4 + 4 + 4 * 8; }

template <typename T>
size_t bytesOf(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

size_t imagesSize(const CaptureFrame& f) {
  return bytesOf(f.color_rgb) + bytesOf(f.depth_window) + bytesOf(f.draw_ids) + bytesOf(f.primitive_ids);
}

size_t restSize(const CaptureFrame& f) {
  size_t n = 4;
  for (const DrawRecord& d : f.draws)
    n += kDrawFixedSize + d.texture_keys.size() * 8 + d.deformed_clip_xyzw.size() * 4;
  n += 4;  // unrecorded_draws
  n += 4;
  for (const MeshRecord& m : f.new_meshes)
    n += kMeshFixedSize + m.positions_xyz.size() * 4 + m.indices.size() * 4;
  return n;
}

size_t encodedSize(const CaptureFrame& f) { return headSize(f) + imagesSize(f) + restSize(f); }

class Encoder {
 public:
  explicit Encoder(char* p) : p_(p) {}
  void u8(uint8_t v) { *p_++ = static_cast<char>(v); }
  void u32(uint32_t v) { raw(&v, 4); }
  void u64(uint64_t v) { raw(&v, 8); }
  void f64(double v) { raw(&v, 8); }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  template <typename T>
  void vec(const std::vector<T>& v) {
    u64(v.size());
    raw(v.data(), v.size() * sizeof(T));
  }
  void matrix(const GlMatrix& m) { raw(m.data(), 64); }
  void bytes(const void* src, size_t n) { raw(src, n); }
  char* position() const { return p_; }

 private:
  void raw(const void* src, size_t n) {
    if (n == 0) return;
    std::memcpy(p_, src, n);
    p_ += n;
  }
  char* p_;
};

// Reads fields from [begin, end); every read is checked against the bytes that remain.
// `base` is the payload byte at `begin` (a part's first byte), for the positions in messages.
class Decoder {
 public:
  Decoder(const char* begin, size_t size, size_t base = 0) : begin_(begin), p_(begin), end_(begin + size), base_(base) {}

  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  size_t position() const { return base_ + static_cast<size_t>(p_ - begin_); }

  uint8_t u8(const char* what) {
    need(1, what);
    return static_cast<uint8_t>(*p_++);
  }
  uint32_t u32(const char* what) {
    uint32_t v;
    raw(&v, 4, what);
    return v;
  }
  uint64_t u64(const char* what) {
    uint64_t v;
    raw(&v, 8, what);
    return v;
  }
  double f64(const char* what) {
    double v;
    raw(&v, 8, what);
    return v;
  }
  void str(std::string& s, const char* what) {
    const uint32_t n = u32(what);
    need(n, what);
    s.assign(p_, n);
    p_ += n;
  }
  template <typename T>
  void vec(std::vector<T>& v, const char* what) {
    const uint64_t n = u64(what);
    if (n > remaining() / sizeof(T))
      fail(std::string(what) + " claims " + std::to_string(n) + " elements but only " +
           std::to_string(remaining()) + " bytes remain");
    v.resize(static_cast<size_t>(n));
    raw(v.data(), v.size() * sizeof(T), what);
  }
  /// The elements of a vector whose count came before (version 5 images).
  template <typename T>
  void elements(std::vector<T>& v, uint64_t n, const char* what) {
    if (n > remaining() / sizeof(T))
      fail(std::string(what) + " has " + std::to_string(n) + " elements but only " + std::to_string(remaining()) +
           " bytes remain");
    v.resize(static_cast<size_t>(n));
    raw(v.data(), v.size() * sizeof(T), what);
  }
  void matrix(GlMatrix& m, const char* what) { raw(m.data(), 64, what); }

  /// Reads an element count and checks that `n * min_bytes_each` bytes could follow.
  uint32_t count(const char* what, size_t min_bytes_each) {
    const uint32_t n = u32(what);
    if (n > remaining() / min_bytes_each)
      fail(std::string(what) + " " + std::to_string(n) + " cannot fit in the " +
           std::to_string(remaining()) + " remaining bytes");
    return n;
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw std::runtime_error("frame payload byte " + std::to_string(position()) + ": " + message);
  }

 private:
  void need(size_t n, const char* what) const {
    if (n > remaining())
      fail(std::string("ends inside ") + what + " (needs " + std::to_string(n) + " bytes, " +
           std::to_string(remaining()) + " remain)");
  }
  void raw(void* dst, size_t n, const char* what) {
    need(n, what);
    if (n == 0) return;
    std::memcpy(dst, p_, n);
    p_ += n;
  }

  const char* begin_;
  const char* p_;
  const char* end_;
  size_t base_;
};

void decodeDraw(Decoder& in, DrawRecord& d, uint32_t version) {
  d.index = in.u32("draw index");
  d.mesh_key = in.u64("draw mesh_key");
  d.vertex_buffer_key = in.u64("draw vertex_buffer_key");
  d.index_buffer_key = in.u64("draw index_buffer_key");
  d.program_key = in.u64("draw program_key");
  const uint32_t textures = in.count("draw texture count", 8);
  d.texture_keys.resize(textures);
  for (uint64_t& key : d.texture_keys) key = in.u64("draw texture key");
  d.matrix_flags = in.u8("draw matrix_flags");
  in.matrix(d.world, "draw world matrix");
  in.matrix(d.view, "draw view matrix");
  in.matrix(d.projection, "draw projection matrix");
  d.primitive_mode = in.u32("draw primitive_mode");
  d.primitive_count = in.u32("draw primitive_count");
  d.visible_pixels = in.u32("draw visible_pixels");
  d.gaps = version >= 2 ? in.u8("draw gaps") : 0;
  in.vec(d.deformed_clip_xyzw, "draw deformed_clip_xyzw");
}

void encodeHead(const CaptureFrame& f, Encoder& e) {
  e.u64(f.number);
  e.f64(f.time_s);
  e.str(f.condition);
  e.u32(f.width);
  e.u32(f.height);
  e.u64(f.color_rgb.size());
  e.u64(f.depth_window.size());
  e.u64(f.draw_ids.size());
  e.u64(f.primitive_ids.size());
}

void encodeRest(const CaptureFrame& f, Encoder& e) {
  e.u32(static_cast<uint32_t>(f.draws.size()));
  for (const DrawRecord& d : f.draws) {
    e.u32(d.index);
    e.u64(d.mesh_key);
    e.u64(d.vertex_buffer_key);
    e.u64(d.index_buffer_key);
    e.u64(d.program_key);
    e.u32(static_cast<uint32_t>(d.texture_keys.size()));
    for (uint64_t key : d.texture_keys) e.u64(key);
    e.u8(d.matrix_flags);
    e.matrix(d.world);
    e.matrix(d.view);
    e.matrix(d.projection);
    e.u32(d.primitive_mode);
    e.u32(d.primitive_count);
    e.u32(d.visible_pixels);
    e.u8(d.gaps);
    e.vec(d.deformed_clip_xyzw);
  }
  e.u32(f.unrecorded_draws);
  e.u32(static_cast<uint32_t>(f.new_meshes.size()));
  for (const MeshRecord& m : f.new_meshes) {
    e.u64(m.key);
    e.vec(m.positions_xyz);
    e.vec(m.indices);
  }
}

// Number to height, the fields every version begins with.
void decodeHeadFields(Decoder& in, CaptureFrame& f) {
  f.number = in.u64("frame number");
  f.time_s = in.f64("time_s");
  in.str(f.condition, "condition");
  f.width = in.u32("width");
  f.height = in.u32("height");
  if (f.width > kMaxImageSide || f.height > kMaxImageSide)
    in.fail("image size " + std::to_string(f.width) + "x" + std::to_string(f.height) +
            " exceeds the limit of " + std::to_string(kMaxImageSide) + " per side");
}

void decodeCounts(Decoder& in, capture_format::ImageCounts& counts) {
  for (int k = 0; k < capture_format::kImages; ++k) counts.n[k] = in.u64(capture_format::kImageNames[k]);
}

void decodeRestFields(Decoder& in, CaptureFrame& f, uint32_t version) {
  const uint32_t draws = in.count("draw count", version >= 2 ? kDrawFixedSize : kDrawFixedSizeV1);
  f.draws.resize(draws);
  for (DrawRecord& d : f.draws) decodeDraw(in, d, version);
  f.unrecorded_draws = version >= 2 ? in.u32("unrecorded_draws") : 0;
  const uint32_t meshes = in.count("mesh count", kMeshFixedSize);
  f.new_meshes.resize(meshes);
  for (MeshRecord& m : f.new_meshes) {
    m.key = in.u64("mesh key");
    in.vec(m.positions_xyz, "mesh positions_xyz");
    in.vec(m.indices, "mesh indices");
  }
  if (in.remaining() != 0) in.fail(std::to_string(in.remaining()) + " trailing bytes after the frame");
}

}  // namespace

size_t capture_format::ImageCounts::bytes(int k) const { return static_cast<size_t>(n[k]) * kImageElementBytes[k]; }

capture_format::ImageCounts capture_format::imageCounts(const CaptureFrame& f) {
  return ImageCounts{{f.color_rgb.size(), f.depth_window.size(), f.draw_ids.size(), f.primitive_ids.size()}};
}

void capture_format::encodePayloadHead(const CaptureFrame& f, std::string& out) {
  out.resize(headSize(f));
  Encoder e(&out[0]);
  encodeHead(f, e);
}

void capture_format::encodePayloadRest(const CaptureFrame& f, std::string& out) {
  out.resize(restSize(f));
  Encoder e(&out[0]);
  encodeRest(f, e);
  if (e.position() != out.data() + out.size())
    throw std::logic_error("encodePayloadRest: size computation does not match the encoder");
}

void capture_format::decodePayloadHead(const char* data, size_t size, CaptureFrame& f, ImageCounts& counts) {
  Decoder in(data, size);
  decodeHeadFields(in, f);
  decodeCounts(in, counts);
  if (in.remaining() != 0) in.fail(std::to_string(in.remaining()) + " trailing bytes after the head");
}

void capture_format::decodePayloadRest(const char* data, size_t size, size_t at, CaptureFrame& f, uint32_t version) {
  Decoder in(data, size, at);
  decodeRestFields(in, f, version);
}

size_t capture_format::payloadSize(const CaptureFrame& f) { return encodedSize(f); }

void encodeFramePayload(const CaptureFrame& f, std::string& out) {
  out.resize(encodedSize(f));
  Encoder e(&out[0]);
  encodeHead(f, e);
  e.bytes(f.color_rgb.data(), bytesOf(f.color_rgb));
  e.bytes(f.depth_window.data(), bytesOf(f.depth_window));
  e.bytes(f.draw_ids.data(), bytesOf(f.draw_ids));
  e.bytes(f.primitive_ids.data(), bytesOf(f.primitive_ids));
  encodeRest(f, e);
  if (e.position() != out.data() + out.size())
    throw std::logic_error("encodeFramePayload: size computation does not match the encoder");
}

std::string encodeFramePayload(const CaptureFrame& frame) {
  std::string out;
  encodeFramePayload(frame, out);
  return out;
}

void decodeFramePayload(const char* data, size_t size, CaptureFrame& f, uint32_t version) {
  Decoder in(data, size);
  decodeHeadFields(in, f);
  if (version >= 5) {
    capture_format::ImageCounts counts;
    decodeCounts(in, counts);
    in.elements(f.color_rgb, counts.n[0], "color_rgb");
    in.elements(f.depth_window, counts.n[1], "depth_window");
    in.elements(f.draw_ids, counts.n[2], "draw_ids");
    in.elements(f.primitive_ids, counts.n[3], "primitive_ids");
  } else {
    in.vec(f.color_rgb, "color_rgb");
    in.vec(f.depth_window, "depth_window");
    in.vec(f.draw_ids, "draw_ids");
    in.vec(f.primitive_ids, "primitive_ids");
  }
  decodeRestFields(in, f, version);
}

CaptureFrame decodeFramePayload(const std::string& payload) {
  CaptureFrame frame;
  decodeFramePayload(payload.data(), payload.size(), frame);
  return frame;
}

}  // namespace viper
