// CaptureReader: reads and verifies a .vcap stream, optionally following a file still being written.
#include "viper/capture/capture_stream.h"

#include "capture_stream_codec.h"
#include "capture_stream_format.h"

#include <xxhash.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace viper {

using namespace capture_format;

struct CaptureReader::Impl {
  std::string path;
  std::FILE* file = nullptr;
  CaptureHeader header;
  uint64_t offset = 0;
  bool ended = false;
  std::unique_ptr<PartCodec> codec;  // the header's codec
  ByteBuffer compressed;  // reused between frames
  ByteBuffer raw;
  CaptureImageSink* sink = nullptr;

  ~Impl() {
    if (file) std::fclose(file);
  }

  [[noreturn]] void fail(uint64_t at, const std::string& what) const { throw CaptureFormatError(path, at, what); }

  // Current size of the file: it may grow between calls while a writer appends.
  uint64_t fileSize() {
    const int fd = fileno(file);
    struct stat st;
    if (fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) return static_cast<uint64_t>(st.st_size);
    if (fseeko(file, 0, SEEK_END) != 0) fail(offset, std::string("cannot seek: ") + std::strerror(errno));
    const off_t end = ftello(file);
    if (end < 0) fail(offset, std::string("cannot tell size: ") + std::strerror(errno));
    return static_cast<uint64_t>(end);
  }

  // Positions the stream at `at`, dropping stdio's EOF flag and buffer so newly appended bytes show.
  void seekTo(uint64_t at) {
    std::clearerr(file);
    if (fseeko(file, static_cast<off_t>(at), SEEK_SET) != 0)
      fail(at, std::string("cannot seek: ") + std::strerror(errno));
  }

  bool readExact(char* dst, size_t n) { return std::fread(dst, 1, n, file) == n; }

  void readHeader();
  Status readChunk(CaptureFrame& frame, bool follow, bool images);
  void decodeParts(uint64_t start, const std::string& which, uint64_t csize, uint64_t rsize, CaptureFrame& frame,
                   bool images);
  void decodeSixParts(uint64_t start, const std::string& which, uint64_t csize, uint64_t rsize, CaptureFrame& frame,
                      bool images);
  void findParts(uint64_t start, const std::string& which, uint64_t csize, uint64_t rsize, CompressedPart* part,
                 int count) {
    try {
      codec->find(compressed.data(), csize, rsize, part, count);
    } catch (const std::runtime_error& e) {
      fail(start, which + e.what());
    }
  }
  void toSink(CaptureFrame& frame);

  void decompress(uint64_t start, const std::string& which, const char* src, size_t src_size, char* dst,
                  size_t dst_size) {
    try {
      codec->decompress(src, src_size, dst, dst_size);
    } catch (const std::runtime_error& e) {
      fail(start, which + e.what());
    }
  }

  void decode(uint64_t start, const std::string& which, const char* data, size_t size, CaptureFrame& frame) {
    try {
      decodeFramePayload(data, size, frame, header.version);
    } catch (const std::runtime_error& e) {
      fail(start, which + e.what());
    }
  }

  static void clearImages(CaptureFrame& frame) {
    frame.color_rgb.clear();
    frame.depth_window.clear();
    frame.draw_ids.clear();
    frame.primitive_ids.clear();
  }
};

namespace {

// The frame's vector of image `k` (payload order), as bytes.
template <typename Visit>
void withImage(CaptureFrame& frame, int k, Visit visit) {
  switch (k) {
    case 0: visit(frame.color_rgb); break;
    case 1: visit(frame.depth_window); break;
    case 2: visit(frame.draw_ids); break;
    default: visit(frame.primitive_ids); break;
  }
}

}  // namespace

// Versions before 5 decode the images into the frame's vectors; each one the sink takes is copied there once.
void CaptureReader::Impl::toSink(CaptureFrame& frame) {
  for (int k = 0; k < kImages; ++k) {
    withImage(frame, k, [&](auto& v) {
      const size_t bytes = v.size() * sizeof(v[0]);
      if (bytes == 0) return;
      void* dst = sink->imageStorage(static_cast<CaptureImage>(k), frame, bytes);
      if (!dst) return;
      std::memcpy(dst, v.data(), bytes);
      v.clear();
    });
  }
}

// A version 5 payload: the head tells the images' sizes, each image is decompressed straight into
// the sink's storage or the frame's vector (or skipped), then the rest.
void CaptureReader::Impl::decodeSixParts(uint64_t start, const std::string& which, uint64_t csize, uint64_t rsize,
                                         CaptureFrame& frame, bool images) {
  const char* src = compressed.data();
  CompressedPart part[kPartsV5];
  findParts(start, which, csize, rsize, part, kPartsV5);
  const size_t largest = std::max(part[0].content, part[5].content);
  raw.reserveDiscard(largest);
  decompress(start, which, src + part[0].begin, part[0].size, raw.data(), part[0].content);
  ImageCounts counts;
  try {
    decodePayloadHead(raw.data(), part[0].content, frame, counts);
  } catch (const std::runtime_error& e) {
    fail(start, which + e.what());
  }
  for (int k = 0; k < kImages; ++k) {
    // A count is at most the payload's bytes, so that the product cannot overflow.
    if (counts.n[k] > rsize || counts.bytes(k) != part[1 + k].content)
      fail(start, which + kImageNames[k] + ": the head says " + std::to_string(counts.n[k]) + " elements, its part holds " +
                      std::to_string(part[1 + k].content) + " bytes");
  }
  if (!images) {
    clearImages(frame);
  } else {
    for (int k = 0; k < kImages; ++k) {
      const size_t bytes = part[1 + k].content;
      void* dst = sink && bytes > 0 ? sink->imageStorage(static_cast<CaptureImage>(k), frame, bytes) : nullptr;
      withImage(frame, k, [&](auto& v) {
        if (dst) {
          v.clear();
        } else {
          v.resize(static_cast<size_t>(counts.n[k]));
          dst = v.data();
        }
      });
      if (bytes > 0) decompress(start, which, src + part[1 + k].begin, part[1 + k].size, static_cast<char*>(dst), bytes);
    }
  }
  decompress(start, which, src + part[5].begin, part[5].size, raw.data(), part[5].content);
  try {
    decodePayloadRest(raw.data(), part[5].content, static_cast<size_t>(rsize - part[5].content), frame,
                      header.version);
  } catch (const std::runtime_error& e) {
    fail(start, which + e.what());
  }
}

void CaptureReader::Impl::readHeader() {
  char fixed[kFileHeaderFixedSize];
  const size_t got = std::fread(fixed, 1, sizeof(fixed), file);
  if (got >= 8 && std::memcmp(fixed, kFileMagic, 8) != 0)
    fail(0, "bad magic: not a viper capture stream (expected \"VIPERCAP\")");
  if (got < sizeof(fixed))
    fail(0, "truncated header: file has " + std::to_string(got) + " of at least " +
                std::to_string(kFileHeaderFixedSize + 8) + " header bytes");
  header.version = getU32(fixed + 8);
  // The version comes before the checksum: a newer writer may lay out the rest differently.
  if (header.version < kOldestReadableCaptureFormatVersion || header.version > kNewestReadableCaptureFormatVersion)
    fail(0, "unsupported capture format version " + std::to_string(header.version) + " (this reader reads versions " +
                std::to_string(kOldestReadableCaptureFormatVersion) + " to " +
                std::to_string(kNewestReadableCaptureFormatVersion) + ")");
  const uint32_t fields_size = getU32(fixed + 12);
  if (fields_size > kMaxHeaderFieldsSize || fields_size < 8)
    fail(0, "header fields size " + std::to_string(fields_size) + " is out of range");
  std::string bytes(kFileHeaderFixedSize + fields_size + 8, '\0');
  std::memcpy(&bytes[0], fixed, sizeof(fixed));
  if (!readExact(&bytes[kFileHeaderFixedSize], fields_size + 8))
    fail(0, "truncated header: " + std::to_string(bytes.size()) + " header bytes expected");
  const char* p = bytes.data();
  if (XXH3_64bits(p, kFileHeaderFixedSize + fields_size) != getU64(p + kFileHeaderFixedSize + fields_size))
    fail(0, "header checksum mismatch");
  // Fields: program, profile (u32 length + bytes each); later versions may append more.
  const char* q = p + kFileHeaderFixedSize;
  const char* end = q + fields_size;
  for (std::string* s : {&header.program, &header.profile}) {
    if (end - q < 4) fail(0, "header fields end early");
    const uint32_t n = getU32(q);
    q += 4;
    if (static_cast<uint64_t>(end - q) < n) fail(0, "header string of " + std::to_string(n) + " bytes overruns the fields");
    s->assign(q, n);
    q += n;
  }
  // From version 4 the codec follows (versions 1 to 3 are zstd).
  header.codec = CaptureCodec::kZstd;
  if (header.version >= 4) {
    if (end - q < 4) fail(0, "header fields end before the codec");
    const uint32_t c = getU32(q);
    if (c != static_cast<uint32_t>(CaptureCodec::kZstd) && c != static_cast<uint32_t>(CaptureCodec::kLz4))
      fail(0, "unknown codec " + std::to_string(c) + " (this reader reads 1 = zstd, 2 = lz4)");
    header.codec = static_cast<CaptureCodec>(c);
  }
  codec.reset(new PartCodec(header.codec));
  offset = bytes.size();
}

// The three parts of a version 3 or 4 payload (head, images, rest) are found by their headers alone
// (zstd's frame and block headers, the LZ4 parts' size headers; nothing is decompressed). Every part is
// checked the same way whether or not its images are wanted: the checksum of the compressed bytes
// covers the skipped images, so damage there is still reported at this chunk.
void CaptureReader::Impl::decodeParts(uint64_t start, const std::string& which, uint64_t csize, uint64_t rsize,
                                      CaptureFrame& frame, bool images) {
  const char* src = compressed.data();
  CompressedPart part[kPartsV3];
  findParts(start, which, csize, rsize, part, kPartsV3);
  if (images) {
    raw.reserveDiscard(rsize);
    size_t out = 0;
    for (int k = 0; k < kPartsV3; ++k) {
      decompress(start, which, src + part[k].begin, part[k].size, raw.data() + out, part[k].content);
      out += part[k].content;
    }
    decode(start, which, raw.data(), rsize, frame);
    return;
  }
  // The payload without its images: the images part replaced by four empty vectors, decoded by the
  // same bounds-checked decoder as a whole payload.
  const size_t head = part[0].content, rest = part[2].content;
  const size_t bytes = head + kEmptyImagesBytes + rest;
  raw.reserveDiscard(bytes);
  decompress(start, which, src + part[0].begin, part[0].size, raw.data(), head);
  std::memset(raw.data() + head, 0, kEmptyImagesBytes);
  decompress(start, which, src + part[2].begin, part[2].size, raw.data() + head + kEmptyImagesBytes, rest);
  decode(start, which, raw.data(), bytes, frame);
}

CaptureReader::Status CaptureReader::Impl::readChunk(CaptureFrame& frame, bool follow, bool images) {
  const uint64_t start = offset;
  const uint64_t size = fileSize();
  const uint64_t avail = size > start ? size - start : 0;
  seekTo(start);
  char h[kChunkHeaderSize];
  if (avail < kChunkHeaderSize || !readExact(h, kChunkHeaderSize)) {
    if (follow) {
      seekTo(start);
      return Status::kPending;
    }
    if (avail == 0) fail(start, "truncated: end of file without end-of-stream marker");
    fail(start, "truncated: chunk header incomplete (" + std::to_string(avail) + " of " +
                    std::to_string(kChunkHeaderSize) + " bytes)");
  }
  if (std::memcmp(h, kChunkMagic, 4) != 0) fail(start, "bad chunk magic (expected \"VCHK\")");
  if (XXH3_64bits(h, kChunkHeaderCheckedSize) != getU64(h + 40)) fail(start, "chunk header checksum mismatch");
  const uint32_t type = getU32(h + 4);
  const uint64_t number = getU64(h + 8);
  const uint64_t csize = getU64(h + 16);
  const uint64_t rsize = getU64(h + 24);
  const std::string which = "frame " + std::to_string(number) + ": ";
  if (type == kChunkEnd) {
    if (csize != 0 || rsize != 0) fail(start, "end-of-stream chunk with a payload");
    ended = true;
    offset = start + kChunkHeaderSize;
    return Status::kEnd;
  }
  if (type != kChunkFrame) fail(start, "unknown chunk type " + std::to_string(type));
  if (rsize > kMaxRawPayloadBytes || csize > codec->maxCompressed())
    fail(start, which + "payload sizes out of range (compressed " + std::to_string(csize) + ", raw " +
                    std::to_string(rsize) + ")");
  if (avail - kChunkHeaderSize < csize) {
    if (follow) {
      seekTo(start);
      return Status::kPending;
    }
    fail(start, which + "truncated: chunk needs " + std::to_string(csize) + " payload bytes, file has " +
                    std::to_string(avail - kChunkHeaderSize));
  }
  compressed.reserveDiscard(csize);
  if (!readExact(compressed.data(), csize)) {
    if (follow) {
      seekTo(start);
      return Status::kPending;
    }
    fail(start, which + "truncated: short read of the payload");
  }
  if (XXH3_64bits(compressed.data(), csize) != getU64(h + 32)) fail(start, which + "payload checksum mismatch");
  if (header.version >= 5) {
    decodeSixParts(start, which, csize, rsize, frame, images);
  } else if (header.version >= 3) {
    decodeParts(start, which, csize, rsize, frame, images);
    if (images && sink) toSink(frame);
  } else {
    // Versions 1 and 2 compress the payload as one zstd frame: the images cannot be skipped.
    const unsigned long long content = ZSTD_getFrameContentSize(compressed.data(), csize);
    if (content != rsize)
      fail(start, which + "zstd frame declares " +
                      (content >= ZSTD_CONTENTSIZE_ERROR ? std::string("no valid size") : std::to_string(content)) +
                      ", chunk header says " + std::to_string(rsize) + " bytes");
    raw.reserveDiscard(rsize);
    decompress(start, which, compressed.data(), csize, raw.data(), rsize);
    decode(start, which, raw.data(), rsize, frame);
    if (!images) clearImages(frame);
    if (images && sink) toSink(frame);
  }
  if (frame.number != number)
    fail(start, which + "payload holds frame number " + std::to_string(frame.number));
  offset = start + kChunkHeaderSize + csize;
  return Status::kFrame;
}

CaptureReader::CaptureReader(const std::string& path) : impl_(new Impl) {
  impl_->path = path;
  impl_->file = std::fopen(path.c_str(), "rb");
  if (!impl_->file) throw std::runtime_error("cannot open capture stream " + path + ": " + std::strerror(errno));
  impl_->readHeader();
}

CaptureReader::CaptureReader(std::FILE* file, const std::string& name) : impl_(new Impl) {
  impl_->path = name;
  impl_->file = file;
  if (!impl_->file) throw std::runtime_error("capture stream " + name + ": no file given");
  impl_->readHeader();
}

CaptureReader::~CaptureReader() = default;

const CaptureHeader& CaptureReader::header() const { return impl_->header; }

CaptureReader::Status CaptureReader::next(CaptureFrame& frame, bool follow) {
  if (impl_->ended) return Status::kEnd;
  return impl_->readChunk(frame, follow, true);
}

CaptureReader::Status CaptureReader::nextWithoutImages(CaptureFrame& frame, bool follow) {
  if (impl_->ended) return Status::kEnd;
  return impl_->readChunk(frame, follow, false);
}

void CaptureReader::setImageSink(CaptureImageSink* sink) { impl_->sink = sink; }

uint64_t CaptureReader::offset() const { return impl_->offset; }

const std::string& CaptureReader::path() const { return impl_->path; }

}  // namespace viper
