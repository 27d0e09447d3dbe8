// Round trips, header checks, live following and frame validation of the capture stream.
#include "test_capture_stream_frames.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

namespace viper {
namespace {

using test::expectFrameEq;
using test::makeFrame;
using test::TempPath;

TEST(CaptureStream, RoundTripsSeveralFramesAndHeader) {
  TempPath tmp("roundtrip");
  const std::vector<uint64_t> offsets = test::writeStream(tmp.path, 5);
  CaptureReader reader(tmp.path);
  EXPECT_EQ(reader.header().version, kCaptureFormatVersion);
  EXPECT_EQ(reader.header().program, "town");
  EXPECT_EQ(reader.header().profile, "town_profile.yaml");
  CaptureFrame frame;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(reader.offset(), offsets[i]);
    ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame) << "frame " << i;
    expectFrameEq(frame, makeFrame(uint64_t(i)));
    EXPECT_EQ(validateFrame(frame), "");
  }
  EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd);
  EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd) << "end is sticky";
}

TEST(CaptureStream, RoundTripsEmptyFrameAndEmptyHeader) {
  for (CaptureCodec codec : {CaptureCodec::kZstd, CaptureCodec::kLz4}) {
    SCOPED_TRACE(captureCodecName(codec));
    TempPath tmp("empty");
    CaptureFrame empty;
    empty.number = 7;
    CaptureFrame no_pixels_with_draw = makeFrame(8, 0, 0);
    no_pixels_with_draw.draws[0].texture_keys.clear();
    {
      CaptureHeader header;
      header.codec = codec;
      CaptureWriter writer(tmp.path, header);
      writer.write(empty);
      writer.write(no_pixels_with_draw);
    }  // the destructor writes the end marker
    CaptureReader reader(tmp.path);
    EXPECT_EQ(reader.header().program, "");
    EXPECT_EQ(reader.header().profile, "");
    CaptureFrame frame = makeFrame(99);  // stale contents must be replaced, not merged
    ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
    expectFrameEq(frame, empty);
    ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
    expectFrameEq(frame, no_pixels_with_draw);
    EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd);
  }
}

TEST(CaptureStream, RoundTripsFullHdFrame) {
  for (CaptureCodec codec : {CaptureCodec::kZstd, CaptureCodec::kLz4}) {
    SCOPED_TRACE(captureCodecName(codec));
    TempPath tmp("fullhd");
    const CaptureFrame big = makeFrame(3, 1920, 1080);
    CaptureHeader header;
    header.codec = codec;
    CaptureWriter writer(tmp.path, header, 1);
    writer.write(big);
    writer.write(makeFrame(4));
    writer.close();
    writer.close();  // idempotent
    EXPECT_THROW(writer.write(big), std::runtime_error);
    EXPECT_LT(writer.bytesWritten(), encodeFramePayload(big).size() / 2) << "the images are compressed";
    CaptureReader reader(tmp.path);
    CaptureFrame frame;
    ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
    expectFrameEq(frame, big);
    ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);  // a smaller frame into reused buffers
    expectFrameEq(frame, makeFrame(4));
    EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd);
  }
}

TEST(CaptureStream, PayloadCodecRoundTripsAndRejectsTrailingBytes) {
  const CaptureFrame f = makeFrame(2);
  std::string payload = encodeFramePayload(f);
  expectFrameEq(decodeFramePayload(payload), f);
  payload.push_back('x');
  try {
    decodeFramePayload(payload);
    FAIL() << "trailing byte accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("trailing"), std::string::npos) << e.what();
  }
}

TEST(CaptureStream, PayloadDecoderReadsVersion1) {
  // Version 1 had no per-draw gaps and no unrecorded_draws: the same frame without those 5 bytes.
  CaptureFrame f = makeFrame(4);
  f.draws.resize(1);
  f.draws[0].gaps = 0;
  f.new_meshes.clear();
  f.unrecorded_draws = 0;
  const std::string v2 = test::toVersion4Payload(encodeFramePayload(f));
  // ... u8 gaps, u64 deformed count (0), u32 unrecorded_draws, u32 mesh count (0).
  std::string v1 = v2;
  v1.erase(v1.size() - 8, 4);
  v1.erase(v1.size() - 1 - 8 - 4, 1);
  CaptureFrame read;
  decodeFramePayload(v2.data(), v2.size(), read, 4);
  expectFrameEq(read, f);
  decodeFramePayload(v1.data(), v1.size(), read, 1);
  expectFrameEq(read, f);
  EXPECT_THROW(decodeFramePayload(v1.data(), v1.size(), read, 2), std::runtime_error) << "not a version 2 payload";
}

TEST(CaptureStream, PayloadDecoderRejectsEveryTruncation) {
  const std::string payload = encodeFramePayload(makeFrame(2, 8, 4));
  for (size_t cut = 0; cut < payload.size(); ++cut)
    EXPECT_THROW(decodeFramePayload(payload.substr(0, cut)), std::runtime_error) << "cut " << cut;
}

TEST(CaptureStream, PayloadDecoderRejectsHugeCountsWithoutAllocating) {
  std::string payload = encodeFramePayload(makeFrame(1, 4, 4));
  // Offset of color_rgb's element count: number, time, condition (4 + "rain"), width, height.
  const size_t count_at = 8 + 8 + 4 + 4 + 4 + 4;
  const uint64_t huge = uint64_t(1) << 60;
  std::memcpy(&payload[count_at], &huge, 8);
  try {
    decodeFramePayload(payload);
    FAIL() << "huge count accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("color_rgb"), std::string::npos) << e.what();
  }
  std::string wide = encodeFramePayload(makeFrame(1, 4, 4));
  const uint32_t too_wide = 20000;
  std::memcpy(&wide[8 + 8 + 4 + 4], &too_wide, 4);
  EXPECT_THROW(decodeFramePayload(wide), std::runtime_error);
}

void expectHeaderError(const std::string& path, const std::string& needle) {
  try {
    CaptureReader reader(path);
    FAIL() << "opened a stream that should be rejected for: " << needle;
  } catch (const CaptureFormatError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_EQ(e.offset(), 0u);
    EXPECT_EQ(e.file(), path);
  }
}

TEST(CaptureStream, RejectsNewerVersionBadMagicAndDamagedHeader) {
  TempPath tmp("header");
  test::writeStream(tmp.path, 1);
  const std::string good = test::readBytes(tmp.path);

  std::string newer = good;
  newer[8] = 6;  // version field, little-endian u32 at byte 8
  test::writeBytes(tmp.path, newer);
  expectHeaderError(tmp.path, "version 6 (this reader reads versions 1 to 5)");

  std::string magic = good;
  magic[0] = 'X';
  test::writeBytes(tmp.path, magic);
  expectHeaderError(tmp.path, "magic");

  std::string program = good;
  program[20] ^= 1;  // first byte of the program name
  test::writeBytes(tmp.path, program);
  expectHeaderError(tmp.path, "header checksum");

  test::writeBytes(tmp.path, good.substr(0, 12));
  expectHeaderError(tmp.path, "truncated header");

  EXPECT_THROW(CaptureReader("/nonexistent/dir/x.vcap"), std::runtime_error);
  EXPECT_THROW(CaptureWriter("/nonexistent/dir/x.vcap", CaptureHeader{}), std::runtime_error);
}

TEST(CaptureStream, ReadsFromMemoryStream) {
  TempPath tmp("memory");
  test::writeStream(tmp.path, 2);
  std::string bytes = test::readBytes(tmp.path);
  CaptureReader reader(fmemopen(&bytes[0], bytes.size(), "rb"), "memory");
  CaptureFrame frame;
  ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
  expectFrameEq(frame, makeFrame(0));
  ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
  expectFrameEq(frame, makeFrame(1));
  EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd);
}

// A writer thread produces frames slowly; the follower must see each of them, in order, then the end.
TEST(CaptureStream, FollowsALiveWriter) {
  TempPath tmp("live");
  constexpr int kFrames = 12;
  std::atomic<bool> header_written{false};
  std::thread producer([&] {
    CaptureHeader header;
    header.program = "live";
    CaptureWriter writer(tmp.path, header, 1);
    header_written = true;
    for (int i = 0; i < kFrames; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(15));
      writer.write(makeFrame(uint64_t(i), 320, 240));
    }
    writer.close();
  });
  while (!header_written) std::this_thread::yield();
  CaptureReader reader(tmp.path);
  CaptureFrame frame;
  int received = 0;
  int pending = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (;;) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "follower stalled after " << received << " frames";
    const CaptureReader::Status status = reader.next(frame, true);
    if (status == CaptureReader::Status::kEnd) break;
    if (status == CaptureReader::Status::kPending) {
      ++pending;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    ASSERT_EQ(frame.number, uint64_t(received));
    expectFrameEq(frame, makeFrame(uint64_t(received), 320, 240));
    ++received;
  }
  producer.join();
  EXPECT_EQ(received, kFrames);
  EXPECT_GT(pending, 0) << "the follower never had to wait, so following was not exercised";
}

TEST(ValidateFrame, AcceptsAGoodFrame) { EXPECT_EQ(validateFrame(makeFrame(4)), ""); }

void expectInvalid(const CaptureFrame& f, const std::string& needle) {
  const std::string problem = validateFrame(f);
  EXPECT_NE(problem.find(needle), std::string::npos) << "problem: '" << problem << "', expected '" << needle << "'";
}

TEST(ValidateFrame, RejectsWrongImageSizes) {
  CaptureFrame f = makeFrame(1);
  f.color_rgb.pop_back();
  expectInvalid(f, "color_rgb has 9215 elements, expected 9216");
  f = makeFrame(1);
  f.depth_window.resize(10);
  expectInvalid(f, "depth_window");
  f = makeFrame(1);
  f.primitive_ids.clear();
  expectInvalid(f, "primitive_ids");
  f = makeFrame(1);
  f.height = 47;
  expectInvalid(f, "expected");
}

TEST(ValidateFrame, RejectsUnknownGapBits) {
  CaptureFrame f = makeFrame(2);
  f.draws[1].gaps = 0x80;
  EXPECT_NE(validateFrame(f).find("draw 1 has unknown gap bits 128"), std::string::npos) << validateFrame(f);
}

TEST(ValidateFrame, RejectsNonSequentialDrawIndices) {
  CaptureFrame f = makeFrame(1);
  f.draws[1].index = 5;
  expectInvalid(f, "draw 1 has index 5");
}

TEST(ValidateFrame, RejectsIdPastTheDrawList) {
  CaptureFrame f = makeFrame(1);
  f.draw_ids[64 * 10 + 3] = 4;  // only 3 draws: ids 1..3
  expectInvalid(f, "pixel (3, 10) has draw id 4 but the draw list has only 3 draws");
}

// The largest id at every position and every length around the vector blocks (8 ids), and ids of
// the top bit (unsigned, not signed, comparison), against std::max_element.
TEST(ValidateFrame, LargestDrawIdIsTheMaximumAnywhere) {
  EXPECT_EQ(largestDrawId(nullptr, 0), 0u);
  for (size_t n : {1, 7, 8, 9, 31, 64, 1000}) {
    for (size_t at = 0; at < n; at += std::max<size_t>(1, n / 9)) {
      std::vector<uint32_t> ids(n);
      for (size_t i = 0; i < n; ++i) ids[i] = static_cast<uint32_t>((i * 2654435761u) % 50);
      for (uint32_t top : {77u, 0x80000001u, 0xffffffffu}) {
        ids[at] = top;
        EXPECT_EQ(largestDrawId(ids.data(), n), *std::max_element(ids.begin(), ids.end())) << n << " " << at;
      }
    }
  }
  CaptureFrame f = makeFrame(1);
  f.draw_ids.back() = 0x80000000u;  // negative as a signed id
  expectInvalid(f, "has draw id 2147483648 but the draw list has only 3 draws");
}

TEST(ValidateFrame, RejectsMalformedGeometry) {
  CaptureFrame f = makeFrame(2);
  f.new_meshes[0].indices.back() = 4;  // 4 vertices
  expectInvalid(f, "index 4 is past its 4 vertices");
  f = makeFrame(2);
  f.draws[2].deformed_clip_xyzw.pop_back();
  expectInvalid(f, "multiple of 4");
}

}  // namespace
}  // namespace viper
