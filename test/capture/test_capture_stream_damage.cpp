// Truncated and corrupted streams: every frame before the damage comes back intact, the damage is
// reported as a CaptureFormatError naming the file, frame and chunk offset, and nothing crashes;
// the same whether frames are read whole or without their images, and for every codec (zstd, LZ4).
#include "test_capture_stream_frames.h"

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace {

using test::expectFrameEq;
using test::makeFrame;

constexpr int kFrames = 3;

// A small stream of kFrames frames; `chunks` holds kFrames + 2 offsets: every chunk's start
// (the last chunk is the end marker) and the file size.
struct SmallStream {
  SmallStream(const std::string& tag, CaptureCodec codec) : tmp(tag + "_" + captureCodecName(codec)) {
    chunks = test::writeStream(tmp.path, kFrames, 16, 12, codec);
    bytes = test::readBytes(tmp.path);
    chunks.push_back(bytes.size());
  }
  // Index of the chunk that holds byte `at` (-1: the file header).
  int chunkOf(uint64_t at) const {
    for (int k = kFrames; k >= 0; --k)
      if (at >= chunks[k]) return k;
    return -1;
  }
  test::TempPath tmp;
  std::vector<uint64_t> chunks;
  std::string bytes;
};

// How a test reads: whole frames (next) or without their images (nextWithoutImages), which must
// report damage the same way although it does not decompress the images.
enum class Read { kWhole, kWithoutImages };

CaptureReader::Status readNext(CaptureReader& reader, CaptureFrame& frame, bool follow, Read read) {
  return read == Read::kWhole ? reader.next(frame, follow) : reader.nextWithoutImages(frame, follow);
}

CaptureFrame expected(uint64_t number, Read read) {
  const CaptureFrame frame = makeFrame(number, 16, 12);
  return read == Read::kWhole ? frame : test::withoutImages(frame);
}

// Reads `bytes` (in memory, named like the stream's file) until an error; checks that exactly the
// frames before chunk `damaged` came back intact and that the error names the file and the damaged
// chunk's offset. Returns the error message.
std::string readUntilError(const SmallStream& s, std::string bytes, int damaged, bool follow,
                           Read read = Read::kWhole) {
  CaptureReader reader(fmemopen(&bytes[0], bytes.size(), "rb"), s.tmp.path);
  CaptureFrame frame;
  for (int i = 0; i < damaged; ++i) {
    EXPECT_EQ(readNext(reader, frame, follow, read), CaptureReader::Status::kFrame) << "frame " << i;
    expectFrameEq(frame, expected(uint64_t(i), read));
  }
  try {
    const CaptureReader::Status status = readNext(reader, frame, follow, read);
    ADD_FAILURE() << "damage in chunk " << damaged << " not reported, status " << int(status);
    return {};
  } catch (const CaptureFormatError& e) {
    EXPECT_EQ(e.offset(), s.chunks[damaged]);
    EXPECT_EQ(e.file(), s.tmp.path);
    const std::string what = e.what();
    EXPECT_NE(what.find(s.tmp.path), std::string::npos) << what;
    EXPECT_NE(what.find("offset " + std::to_string(s.chunks[damaged])), std::string::npos) << what;
    return what;
  }
}

// Every test on a stream of each codec.
class CaptureStreamDamage : public ::testing::TestWithParam<CaptureCodec> {};

TEST_P(CaptureStreamDamage, TruncationAtEveryByteIsReportedAfterTheIntactFrames) {
  SmallStream s("truncate", GetParam());
  ASSERT_LT(s.bytes.size(), 20000u) << "keep the stream small: every byte is a test case";
  for (size_t cut = 0; cut < s.bytes.size(); ++cut) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut) + " of " + std::to_string(s.bytes.size()));
    if (cut < s.chunks[0]) {
      test::writeBytes(s.tmp.path, s.bytes.substr(0, cut));
      EXPECT_THROW(CaptureReader reader(s.tmp.path), CaptureFormatError);
      continue;
    }
    // The chunk that starts at or before the cut and does not fit is the damaged one.
    const int k = s.chunkOf(cut);
    for (Read read : {Read::kWhole, Read::kWithoutImages}) {
      const std::string what = readUntilError(s, s.bytes.substr(0, cut), k, false, read);
      EXPECT_NE(what.find("truncated"), std::string::npos) << what << (read == Read::kWhole ? "" : " (without images)");
    }
    if (::testing::Test::HasFailure()) return;  // one failing cut tells enough
  }
}

TEST_P(CaptureStreamDamage, FollowModeWaitsAtEveryCutAndContinuesAfterTheRestArrives) {
  SmallStream s("follow", GetParam());
  std::vector<size_t> cuts;  // every chunk boundary and its neighbours, and a stride through all bytes
  for (int k = 0; k <= kFrames; ++k)
    for (uint64_t at : {s.chunks[k], s.chunks[k] + 1, s.chunks[k] + 47, s.chunks[k] + 48, s.chunks[k + 1] - 1})
      if (at < s.bytes.size()) cuts.push_back(at);
  for (size_t cut = s.chunks[0]; cut < s.bytes.size(); cut += 5) cuts.push_back(cut);
  for (size_t cut : cuts) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut) + " of " + std::to_string(s.bytes.size()));
    test::writeBytes(s.tmp.path, s.bytes.substr(0, cut));
    const int k = s.chunkOf(cut);
    CaptureReader reader(s.tmp.path);
    CaptureFrame frame;
    for (int i = 0; i < k; ++i) ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kFrame);
    ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kPending);
    ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kPending) << "pending must be repeatable";
    EXPECT_EQ(reader.offset(), s.chunks[k]) << "the reader stays at the incomplete chunk";
    test::writeBytes(s.tmp.path, s.bytes.substr(cut), true);
    for (int i = k; i < kFrames; ++i) {
      ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kFrame) << "frame " << i;
      expectFrameEq(frame, makeFrame(uint64_t(i), 16, 12));
    }
    ASSERT_EQ(reader.next(frame, true), CaptureReader::Status::kEnd);
  }
}

TEST_P(CaptureStreamDamage, EveryFlippedByteIsDetectedInItsChunk) {
  SmallStream s("flip", GetParam());
  for (size_t at = 0; at < s.bytes.size(); ++at) {
    for (const char mask : {'\x01', '\x80'}) {
      SCOPED_TRACE("byte " + std::to_string(at) + " xor " + std::to_string(int(uint8_t(mask))));
      std::string damaged = s.bytes;
      damaged[at] ^= mask;
      const int k = s.chunkOf(at);
      if (k < 0) {
        EXPECT_THROW(CaptureReader reader(fmemopen(&damaged[0], damaged.size(), "rb"), "mem"), CaptureFormatError);
        continue;
      }
      const bool follow = at % 2 == 1;  // corruption is an error in follow mode too, never "pending"
      // A flip in the images is found by the payload's checksum when they are not decompressed.
      for (Read read : {Read::kWhole, Read::kWithoutImages}) {
        const std::string what = readUntilError(s, damaged, k, follow, read);
        const bool in_frame_payload = k < kFrames && at >= s.chunks[k] + 48;
        if (in_frame_payload) {
          EXPECT_NE(what.find("frame " + std::to_string(k) + ":"), std::string::npos) << what;
        }
      }
      if (::testing::Test::HasFailure()) return;
    }
  }
}

TEST_P(CaptureStreamDamage, GarbageAfterTheHeaderIsAnErrorNotACrash) {
  SmallStream s("garbage", GetParam());
  std::string bytes = s.bytes.substr(0, s.chunks[0]);
  uint64_t state = 0x9e3779b97f4a7c15ull;
  for (int i = 0; i < 4096; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    bytes.push_back(char(state >> 56));
  }
  test::writeBytes(s.tmp.path, bytes);
  CaptureReader reader(s.tmp.path);
  CaptureFrame frame;
  EXPECT_THROW(reader.next(frame), CaptureFormatError);
}

INSTANTIATE_TEST_SUITE_P(Codecs, CaptureStreamDamage, ::testing::Values(CaptureCodec::kZstd, CaptureCodec::kLz4),
                         [](const ::testing::TestParamInfo<CaptureCodec>& info) {
                           return std::string(captureCodecName(info.param));
                         });

}  // namespace
}  // namespace viper
