// CaptureReader::nextWithoutImages on a real capture of the world made at build time: the same
// frames, draws, mesh keys and meshes as whole frames, images empty and never decompressed, damage
// reported as by next(); the same run captured with LZ4 gives exactly the zstd capture's frames both
// ways; and on version 2 streams, whose payload is one zstd frame.
#include "test_capture_stream_frames.h"

#define XXH_INLINE_ALL
#include <xxhash.h>
#define ZSTD_STATIC_LINKING_ONLY  // ZSTD_frameHeaderSize
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace viper {
namespace {

using test::expectFrameEq;
using test::withoutImages;

const std::string kWorldCapture = VIPER_WORLD_CAPTURE;
const std::string kWorldLz4Capture = VIPER_WORLD_LZ4_CAPTURE;

uint64_t getU64(const std::string& b, size_t at) {
  uint64_t v;
  std::memcpy(&v, b.data() + at, 8);
  return v;
}
void putU64(std::string& b, size_t at, uint64_t v) { std::memcpy(&b[at], &v, 8); }

// Offsets of a stream's chunks (the end marker's last), walked by their headers.
std::vector<size_t> chunkOffsets(const std::string& b) {
  uint32_t fields;
  std::memcpy(&fields, b.data() + 12, 4);
  std::vector<size_t> chunks;
  for (size_t at = 16 + fields + 8; at + 48 <= b.size(); at += 48 + getU64(b, at + 16)) chunks.push_back(at);
  return chunks;
}

// Gives the chunk at `at` the payload `payload` (compressed, `raw` bytes decompressed) and its checksums.
void replacePayload(std::string& b, size_t at, const std::string& payload, uint64_t raw) {
  const uint64_t old_size = getU64(b, at + 16);
  b.replace(at + 48, old_size, payload);
  putU64(b, at + 16, payload.size());
  putU64(b, at + 24, raw);
  putU64(b, at + 32, XXH3_64bits(payload.data(), payload.size()));
  putU64(b, at + 40, XXH3_64bits(b.data() + at, 40));
}

// Fills the content of every compressed block of the zstd frame at `frame` with 0xff, keeping the
// frame and block headers (so the frame is still found and its size known without decompressing
// it): no longer decompressible (the first such block's literals header asks for a Huffman table
// from an earlier block that has none). Returns the number of blocks changed.
int breakCompressedBlocks(char* frame, size_t size) {
  size_t at = ZSTD_frameHeaderSize(frame, size);
  int changed = 0;
  for (;;) {
    const uint32_t h = uint8_t(frame[at]) | uint8_t(frame[at + 1]) << 8 | uint32_t(uint8_t(frame[at + 2])) << 16;
    const uint32_t type = (h >> 1) & 3, block = h >> 3;  // 0 raw, 1 one byte repeated, 2 compressed
    at += 3;
    if (type == 2) std::memset(frame + at, 0xff, block), ++changed;
    at += type == 1 ? 1 : block;
    if (h & 1) return changed;  // the last block
  }
}

std::vector<CaptureFrame> readAll(const std::string& path, bool images) {
  CaptureReader reader(path);
  std::vector<CaptureFrame> frames;
  CaptureFrame frame;
  while ((images ? reader.next(frame) : reader.nextWithoutImages(frame)) == CaptureReader::Status::kFrame)
    frames.push_back(frame);
  return frames;
}

// `broken`, the bytes of `capture` whose chunk `damaged` has undecodable images (its checksums
// matching): a whole read stops at that chunk with `problem`, a read without images gives every frame
// of the intact capture (it never decompresses the images).
void expectOnlyTheWholeReadFails(const std::string& capture, const std::string& broken, size_t damaged,
                                 const std::string& problem) {
  test::TempPath tmp("world_broken_images");
  test::writeBytes(tmp.path, broken);
  CaptureReader whole(tmp.path);
  CaptureFrame frame;
  for (size_t i = 0; i < damaged; ++i) ASSERT_EQ(whole.next(frame), CaptureReader::Status::kFrame);
  try {
    whole.next(frame);
    ADD_FAILURE() << "the whole read decompresses the broken images";
  } catch (const CaptureFormatError& e) {
    EXPECT_EQ(e.offset(), chunkOffsets(broken)[damaged]);
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
  const std::vector<CaptureFrame> expected = readAll(capture, false);
  const std::vector<CaptureFrame> drawn = readAll(tmp.path, false);
  ASSERT_EQ(drawn.size(), expected.size());
  for (size_t i = 0; i < drawn.size(); ++i) expectFrameEq(drawn[i], expected[i]);
}

TEST(CaptureWithoutImages, WorldCaptureGivesTheSameFramesDrawsAndMeshesAsWholeFrames) {
  ASSERT_EQ(CaptureReader(kWorldCapture).header().version, kCaptureFormatVersion)
      << "a capture of this build: its images are a zstd frame of their own";
  const std::vector<CaptureFrame> whole = readAll(kWorldCapture, true);
  const std::vector<CaptureFrame> drawn = readAll(kWorldCapture, false);
  ASSERT_EQ(whole.size(), 20u);
  ASSERT_EQ(drawn.size(), whole.size());
  size_t draws = 0, meshes = 0;
  for (size_t i = 0; i < whole.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(whole[i].number));
    ASSERT_FALSE(whole[i].color_rgb.empty());
    EXPECT_TRUE(drawn[i].color_rgb.empty() && drawn[i].depth_window.empty() && drawn[i].draw_ids.empty() &&
                drawn[i].primitive_ids.empty());
    expectFrameEq(drawn[i], withoutImages(whole[i]));  // number, time, size, every draw's keys, meshes
    draws += whole[i].draws.size();
    meshes += whole[i].new_meshes.size();
  }
  EXPECT_GT(draws, 20u * 10) << "a town has many draws a frame";
  EXPECT_GT(meshes, 10u);
}

TEST(CaptureWithoutImages, ImagesAreSkippedNotDecompressed) {
  // The images' zstd frame of one chunk made undecodable, its checksums made to match: a whole read
  // stops there, a read without images does not notice (it never decompresses them).
  std::string b = test::readBytes(kWorldCapture);
  const std::vector<size_t> chunks = chunkOffsets(b);
  ASSERT_GT(chunks.size(), 5u);
  const size_t at = chunks[3];
  const std::string payload = b.substr(at + 48, getU64(b, at + 16));
  const size_t head = ZSTD_findFrameCompressedSize(payload.data(), payload.size());
  ASSERT_FALSE(ZSTD_isError(head));
  const size_t images = ZSTD_findFrameCompressedSize(payload.data() + head, payload.size() - head);
  ASSERT_FALSE(ZSTD_isError(images));
  ASSERT_GT(images, 1000u);
  std::string broken = payload;
  ASSERT_GT(breakCompressedBlocks(&broken[head], images), 0) << "the images are compressed";
  replacePayload(b, at, broken, getU64(b, at + 24));
  expectOnlyTheWholeReadFails(kWorldCapture, b, 3, "frame 3: zstd decompression failed");
}

TEST(CaptureWithoutImages, Lz4WorldCaptureGivesExactlyTheZstdCapturesFrames) {
  // Two captures of one deterministic run (cmake/dataset.cmake), one per codec.
  CaptureReader lz4(kWorldLz4Capture);
  ASSERT_EQ(lz4.header().codec, CaptureCodec::kLz4);
  ASSERT_EQ(lz4.header().version, kCaptureFormatVersion);
  ASSERT_EQ(CaptureReader(kWorldCapture).header().codec, CaptureCodec::kZstd);
  for (bool images : {true, false}) {
    SCOPED_TRACE(images ? "whole" : "without images");
    const std::vector<CaptureFrame> zstd_frames = readAll(kWorldCapture, images);
    const std::vector<CaptureFrame> lz4_frames = readAll(kWorldLz4Capture, images);
    ASSERT_EQ(zstd_frames.size(), 20u);
    ASSERT_EQ(lz4_frames.size(), zstd_frames.size());
    for (size_t i = 0; i < lz4_frames.size(); ++i) {
      SCOPED_TRACE("frame " + std::to_string(i));
      EXPECT_EQ(lz4_frames[i].color_rgb.empty(), !images);
      // Payloads compared byte for byte: every field, every pixel.
      EXPECT_TRUE(encodeFramePayload(lz4_frames[i]) == encodeFramePayload(zstd_frames[i]));
      expectFrameEq(lz4_frames[i], zstd_frames[i]);
    }
  }
  EXPECT_LT(test::readBytes(kWorldLz4Capture).size(), 3 * test::readBytes(kWorldCapture).size());
}

TEST(CaptureWithoutImages, Lz4ImagesAreSkippedNotDecompressed) {
  // The images' LZ4 block of one chunk made undecodable behind an intact size header, its checksums
  // made to match: a whole read stops there, a read without images does not notice.
  std::string b = test::readBytes(kWorldLz4Capture);
  const std::vector<size_t> chunks = chunkOffsets(b);
  ASSERT_GT(chunks.size(), 5u);
  const size_t at = chunks[3];
  std::string payload = b.substr(at + 48, getU64(b, at + 16));
  uint32_t head_block, images_block;
  std::memcpy(&head_block, payload.data(), 4);
  const size_t images = 8 + head_block;  // the images part: its size header, then its block
  ASSERT_LT(images + 8, payload.size());
  std::memcpy(&images_block, payload.data() + images, 4);
  ASSERT_GT(images_block, 1000u);
  ASSERT_LE(images + 8 + images_block, payload.size());
  // 0xff tokens ask for literal runs longer than the block: malformed, whatever the decoder's path.
  std::memset(&payload[images + 8], 0xff, images_block);
  replacePayload(b, at, payload, getU64(b, at + 24));
  expectOnlyTheWholeReadFails(kWorldLz4Capture, b, 3, "frame 3: lz4 decompression failed");
}

// A capture cut inside a chunk: every frame before it read without images, then "truncated" at it.
void expectTruncationReported(const std::string& capture) {
  const std::string b = test::readBytes(capture);
  const std::vector<size_t> chunks = chunkOffsets(b);
  ASSERT_GT(chunks.size(), 8u);
  const std::vector<CaptureFrame> whole = readAll(capture, true);
  // Cuts inside a chunk header, inside the images, just before the next chunk, and the end marker lost.
  const size_t k = 7;
  for (size_t cut : {chunks[k] + 20, chunks[k] + 48 + (chunks[k + 1] - chunks[k]) / 2, chunks[k + 1] - 1}) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    test::TempPath tmp("world_truncated");
    test::writeBytes(tmp.path, b.substr(0, cut));
    CaptureReader reader(tmp.path);
    CaptureFrame frame;
    for (size_t i = 0; i < k; ++i) {
      ASSERT_EQ(reader.nextWithoutImages(frame), CaptureReader::Status::kFrame);
      expectFrameEq(frame, withoutImages(whole[i]));
    }
    try {
      reader.nextWithoutImages(frame);
      ADD_FAILURE() << "truncation not reported";
    } catch (const CaptureFormatError& e) {
      EXPECT_EQ(e.file(), tmp.path);
      EXPECT_EQ(e.offset(), chunks[k]);
      EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    }
  }
  test::TempPath tmp("world_no_end");
  test::writeBytes(tmp.path, b.substr(0, chunks.back()));
  CaptureReader reader(tmp.path);
  CaptureFrame frame;
  for (size_t i = 0; i < whole.size(); ++i) ASSERT_EQ(reader.nextWithoutImages(frame), CaptureReader::Status::kFrame);
  EXPECT_THROW(reader.nextWithoutImages(frame), CaptureFormatError);
}

TEST(CaptureWithoutImages, TruncatedWorldCaptureReportsTheDamageAfterTheIntactFrames) {
  for (const std::string& capture : {kWorldCapture, kWorldLz4Capture}) {
    SCOPED_TRACE(capture);
    expectTruncationReported(capture);
  }
}

TEST(CaptureWithoutImages, Version2StreamsAreReadBothWays) {
  // A stream of this writer turned into version 2: the header's version, each payload laid out as
  // version 2 lays it out and recompressed as the one zstd frame version 2 has.
  test::TempPath tmp("version2");
  test::writeStream(tmp.path, 3, 16, 12);
  std::string b = test::readBytes(tmp.path);
  const uint32_t version = 2;
  std::memcpy(&b[8], &version, 4);
  uint32_t fields;
  std::memcpy(&fields, b.data() + 12, 4);
  putU64(b, 16 + fields, XXH3_64bits(b.data(), 16 + fields));
  std::vector<size_t> chunks = chunkOffsets(b);
  for (size_t c = chunks.size() - 1; c-- > 0;) {  // from the last frame: offsets before it stay valid
    const size_t at = chunks[c];
    const std::string six = b.substr(at + 48, getU64(b, at + 16));
    std::string v5(getU64(b, at + 24), '\0');
    ASSERT_EQ(ZSTD_decompress(&v5[0], v5.size(), six.data(), six.size()), v5.size());
    const std::string raw = test::toVersion4Payload(v5);
    std::string one(ZSTD_compressBound(raw.size()), '\0');
    one.resize(ZSTD_compress(&one[0], one.size(), raw.data(), raw.size(), 1));
    replacePayload(b, at, one, raw.size());
  }
  test::writeBytes(tmp.path, b);
  CaptureReader whole(tmp.path), drawn(tmp.path);
  EXPECT_EQ(whole.header().version, 2u);
  CaptureFrame a, d;
  for (uint64_t i = 0; i < 3; ++i) {
    ASSERT_EQ(whole.next(a), CaptureReader::Status::kFrame);
    ASSERT_EQ(drawn.nextWithoutImages(d), CaptureReader::Status::kFrame);
    expectFrameEq(a, test::makeFrame(i, 16, 12));
    expectFrameEq(d, withoutImages(test::makeFrame(i, 16, 12)));
  }
  EXPECT_EQ(whole.next(a), CaptureReader::Status::kEnd);
  EXPECT_EQ(drawn.nextWithoutImages(d), CaptureReader::Status::kEnd);
}

}  // namespace
}  // namespace viper
