// The stream's codec: LZ4 streams round trip whole and without images, and every stream names its
// codec in a version 5 header (which a reader of versions 1 to 4 rejects by its version).
// (Empty and full-HD frames of both codecs: test_capture_stream; damage: test_capture_stream_damage.)
#include "test_capture_stream_frames.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <cstring>

namespace viper {
namespace {

using test::expectFrameEq;
using test::makeFrame;
using test::TempPath;

uint32_t getU32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// Replaces the file header's u32 at `at` and makes its checksum match again.
void setHeaderU32(std::string& b, size_t at, uint32_t v) {
  std::memcpy(&b[at], &v, 4);
  const uint32_t fields = getU32(b, 12);
  const uint64_t sum = XXH3_64bits(b.data(), 16 + fields);
  std::memcpy(&b[16 + fields], &sum, 8);
}

TEST(CaptureStreamCodec, NamesParseAndPrint) {
  CaptureCodec c = CaptureCodec::kZstd;
  ASSERT_TRUE(parseCaptureCodec("lz4", c));
  EXPECT_EQ(c, CaptureCodec::kLz4);
  ASSERT_TRUE(parseCaptureCodec("zstd", c));
  EXPECT_EQ(c, CaptureCodec::kZstd);
  EXPECT_FALSE(parseCaptureCodec("LZ4", c));
  EXPECT_FALSE(parseCaptureCodec("", c));
  EXPECT_STREQ(captureCodecName(CaptureCodec::kLz4), "lz4");
  EXPECT_STREQ(captureCodecName(CaptureCodec::kZstd), "zstd");
}

TEST(CaptureStreamCodec, Lz4StreamRoundTripsWholeAndWithoutImages) {
  TempPath tmp("lz4_roundtrip");
  const std::vector<uint64_t> offsets = test::writeStream(tmp.path, 5, 64, 48, CaptureCodec::kLz4);
  CaptureReader whole(tmp.path), drawn(tmp.path);
  EXPECT_EQ(whole.header().version, kCaptureFormatVersion);
  EXPECT_EQ(whole.header().codec, CaptureCodec::kLz4);
  EXPECT_EQ(whole.header().program, "town");
  EXPECT_EQ(whole.header().profile, "town_profile.yaml");
  CaptureFrame a, d;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(whole.offset(), offsets[i]);
    ASSERT_EQ(whole.next(a), CaptureReader::Status::kFrame) << "frame " << i;
    ASSERT_EQ(drawn.nextWithoutImages(d), CaptureReader::Status::kFrame) << "frame " << i;
    expectFrameEq(a, makeFrame(uint64_t(i)));
    expectFrameEq(d, test::withoutImages(makeFrame(uint64_t(i))));
    EXPECT_EQ(validateFrame(a), "");
  }
  EXPECT_EQ(whole.next(a), CaptureReader::Status::kEnd);
  EXPECT_EQ(drawn.nextWithoutImages(d), CaptureReader::Status::kEnd);
}

TEST(CaptureStreamCodec, ZstdStreamsAreVersion5WithTheirCodecAfterTheProfile) {
  TempPath tmp("zstd_v5");
  test::writeStream(tmp.path, 1);
  const std::string b = test::readBytes(tmp.path);
  EXPECT_EQ(getU32(b, 8), 5u);
  ASSERT_EQ(getU32(b, 12), 8u + 4 + 17 + 4) << "program \"town\", profile \"town_profile.yaml\" and the codec";
  EXPECT_EQ(getU32(b, 16 + 8 + 4 + 17), 1u) << "zstd";
  CaptureReader reader(tmp.path);
  EXPECT_EQ(reader.header().version, kCaptureFormatVersion);
  EXPECT_EQ(reader.header().codec, CaptureCodec::kZstd);
}

TEST(CaptureStreamCodec, Lz4StreamsAreVersion5WithTheCodecAfterTheProfile) {
  TempPath tmp("lz4_v5");
  test::writeStream(tmp.path, 2, 16, 12, CaptureCodec::kLz4);
  const std::string good = test::readBytes(tmp.path);
  // A reader of versions 1 to 4 checks the version first and rejects the stream there, instead of
  // taking six parts for three.
  EXPECT_EQ(getU32(good, 8), 5u);
  const uint32_t fields = getU32(good, 12);
  ASSERT_EQ(fields, 8u + 4 + 17 + 4);
  const size_t codec_at = 16 + fields - 4;
  EXPECT_EQ(getU32(good, codec_at), 2u);

  std::string unknown = good;
  setHeaderU32(unknown, codec_at, 3);
  test::writeBytes(tmp.path, unknown);
  try {
    CaptureReader reader(tmp.path);
    FAIL() << "read a stream of an unknown codec";
  } catch (const CaptureFormatError& e) {
    EXPECT_EQ(e.offset(), 0u);
    EXPECT_NE(std::string(e.what()).find("unknown codec 3"), std::string::npos) << e.what();
  }

  // The codec is what tells the payloads apart: an LZ4 stream that claims zstd fails at its first
  // frame, naming it (it is not misread).
  std::string claims_zstd = good;
  setHeaderU32(claims_zstd, codec_at, 1);
  test::writeBytes(tmp.path, claims_zstd);
  CaptureReader reader(tmp.path);
  EXPECT_EQ(reader.header().codec, CaptureCodec::kZstd);
  CaptureFrame frame;
  try {
    reader.next(frame);
    FAIL() << "read LZ4 parts as zstd frames";
  } catch (const CaptureFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 0: zstd frame 1 of 6"), std::string::npos) << e.what();
  }

  // A version 5 header cut before its codec.
  std::string no_codec = good.substr(0, 16 + fields - 4) + good.substr(16 + fields);
  setHeaderU32(no_codec, 12, fields - 4);
  test::writeBytes(tmp.path, no_codec);
  EXPECT_THROW(CaptureReader r(tmp.path), CaptureFormatError);
}

TEST(CaptureStreamCodec, Lz4FollowsALiveWriter) {
  // Follow mode on an LZ4 stream: every chunk appears whole or not at all.
  TempPath tmp("lz4_follow");
  CaptureHeader header;
  header.codec = CaptureCodec::kLz4;
  CaptureWriter writer(tmp.path, header);
  CaptureReader reader(tmp.path);
  CaptureFrame frame;
  EXPECT_EQ(reader.next(frame, true), CaptureReader::Status::kPending);
  for (uint64_t i = 0; i < 3; ++i) {
    writer.write(makeFrame(i, 32, 24));
    ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kFrame);
    expectFrameEq(frame, makeFrame(i, 32, 24));
    EXPECT_EQ(reader.next(frame, true), CaptureReader::Status::kPending);
  }
  writer.close();
  EXPECT_EQ(reader.next(frame, true), CaptureReader::Status::kEnd);
}

}  // namespace
}  // namespace viper
