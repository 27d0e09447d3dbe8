// CaptureFormatError and CaptureWriter: the writing side of the .vcap stream.
#include "viper/capture/capture_stream.h"

#include "capture_stream_codec.h"
#include "capture_stream_format.h"

#include <xxhash.h>

#include <cerrno>
#include <cstring>

namespace viper {

using namespace capture_format;

CaptureFormatError::CaptureFormatError(const std::string& file, uint64_t offset, const std::string& what)
    : std::runtime_error(file + ": offset " + std::to_string(offset) + ": " + what),
      file_(file),
      offset_(offset) {}

namespace {

// Fills the chunk header at `h`, in front of `compressed` bytes placed at h + kChunkHeaderSize.
void fillChunkHeader(char* h, uint32_t type, uint64_t frame_number, size_t compressed, uint64_t raw) {
  std::memcpy(h, kChunkMagic, 4);
  putU32(h + 4, type);
  putU64(h + 8, frame_number);
  putU64(h + 16, compressed);
  putU64(h + 24, raw);
  putU64(h + 32, XXH3_64bits(h + kChunkHeaderSize, compressed));
  putU64(h + 40, XXH3_64bits(h, kChunkHeaderCheckedSize));
}

}  // namespace

struct CaptureChunkEncoder::Impl {
  std::unique_ptr<PartCodec> codec;
  std::string head, rest;  // scratch, reused between frames
  ByteBuffer chunk;        // chunk header + compressed payload, reused between frames
  size_t size = 0;
};

CaptureChunkEncoder::CaptureChunkEncoder(CaptureCodec codec, int zstd_level) : impl_(new Impl) {
  impl_->codec.reset(new PartCodec(codec, zstd_level));
}

CaptureChunkEncoder::~CaptureChunkEncoder() = default;

// The six parts of a version 5 payload (head, the four images, rest) compressed one by one, the
// images straight from the frame's vectors: no copy of the whole payload is made.
void CaptureChunkEncoder::encode(const CaptureFrame& frame, const std::string& stream) {
  Impl& e = *impl_;
  const size_t raw = payloadSize(frame);
  if (raw > kMaxRawPayloadBytes)
    throw std::runtime_error("capture stream " + stream + ": frame " + std::to_string(frame.number) +
                             " payload of " + std::to_string(raw) + " bytes exceeds the 1 GiB limit");
  encodePayloadHead(frame, e.head);
  encodePayloadRest(frame, e.rest);
  const ImageCounts counts = imageCounts(frame);
  const Piece pieces[kPartsV5] = {{e.head.data(), e.head.size()},
                                  {frame.color_rgb.data(), counts.bytes(0)},
                                  {frame.depth_window.data(), counts.bytes(1)},
                                  {frame.draw_ids.data(), counts.bytes(2)},
                                  {frame.primitive_ids.data(), counts.bytes(3)},
                                  {e.rest.data(), e.rest.size()}};
  const size_t bound = e.codec->bound(pieces, kPartsV5);
  e.chunk.reserveDiscard(kChunkHeaderSize + bound);
  size_t compressed;
  try {
    compressed = e.codec->compress(pieces, kPartsV5, e.chunk.data() + kChunkHeaderSize, bound);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error("capture stream " + stream + ": frame " + std::to_string(frame.number) + ": " +
                             error.what());
  }
  fillChunkHeader(e.chunk.data(), kChunkFrame, frame.number, compressed, raw);
  e.size = kChunkHeaderSize + compressed;
}

const char* CaptureChunkEncoder::data() const { return impl_->chunk.data(); }

size_t CaptureChunkEncoder::size() const { return impl_->size; }

struct CaptureWriter::Impl {
  std::string path;
  std::FILE* file = nullptr;
  std::unique_ptr<CaptureChunkEncoder> encoder;
  uint64_t bytes = 0;
  uint64_t frames = 0;

  void writeAll(const char* data, size_t size) {
    if (std::fwrite(data, 1, size, file) != size || std::fflush(file) != 0)
      throw std::runtime_error("writing capture stream " + path + ": " + std::strerror(errno));
    bytes += size;
  }

  ~Impl() {
    if (file) std::fclose(file);
  }
};

CaptureWriter::CaptureWriter(const std::string& path, const CaptureHeader& header, int zstd_level)
    : impl_(new Impl) {
  impl_->path = path;
  try {
    impl_->encoder.reset(new CaptureChunkEncoder(header.codec, zstd_level));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("capture stream " + path + ": " + e.what());
  }
  impl_->file = std::fopen(path.c_str(), "wb");
  if (!impl_->file)
    throw std::runtime_error("cannot open capture stream " + path + " for writing: " + std::strerror(errno));

  // Every stream is version 5, which names its codec after the profile (as version 4 did).
  const uint32_t fields_size = static_cast<uint32_t>(8 + header.program.size() + header.profile.size() + 4);
  if (fields_size > kMaxHeaderFieldsSize)
    throw std::runtime_error("capture stream " + path + ": program/profile names are too long");
  std::string bytes(kFileHeaderFixedSize + fields_size + 8, '\0');
  char* p = &bytes[0];
  std::memcpy(p, kFileMagic, 8);
  putU32(p + 8, kCaptureFormatVersion);
  putU32(p + 12, fields_size);
  char* q = p + kFileHeaderFixedSize;
  for (const std::string* s : {&header.program, &header.profile}) {
    putU32(q, static_cast<uint32_t>(s->size()));
    std::memcpy(q + 4, s->data(), s->size());
    q += 4 + s->size();
  }
  putU32(q, static_cast<uint32_t>(header.codec));
  q += 4;
  putU64(q, XXH3_64bits(p, kFileHeaderFixedSize + fields_size));
  impl_->writeAll(bytes.data(), bytes.size());
}

CaptureWriter::~CaptureWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor must not throw; the stream simply lacks its end marker (readers say "truncated").
  }
}

void CaptureWriter::write(const CaptureFrame& frame) {
  Impl& w = *impl_;
  if (!w.file) throw std::runtime_error("capture stream " + w.path + ": write() after close()");
  w.encoder->encode(frame, w.path);
  writeEncoded(*w.encoder);
}

void CaptureWriter::writeEncoded(const CaptureChunkEncoder& chunk) {
  Impl& w = *impl_;
  if (!w.file) throw std::runtime_error("capture stream " + w.path + ": write() after close()");
  w.writeAll(chunk.data(), chunk.size());
  ++w.frames;
}

void CaptureWriter::close() {
  Impl& w = *impl_;
  if (!w.file) return;
  // The end chunk's frame field holds the number of frames written.
  char end[kChunkHeaderSize];
  fillChunkHeader(end, kChunkEnd, w.frames, 0, 0);
  try {
    w.writeAll(end, kChunkHeaderSize);
  } catch (...) {
    std::fclose(w.file);
    w.file = nullptr;
    throw;
  }
  const int rc = std::fclose(w.file);
  w.file = nullptr;
  if (rc != 0) throw std::runtime_error("closing capture stream " + w.path + ": " + std::strerror(errno));
}

uint64_t CaptureWriter::bytesWritten() const { return impl_->bytes; }

}  // namespace viper
