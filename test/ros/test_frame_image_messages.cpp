// CaptureReader's image sink and the bridge's sink, FrameImageMessages (no roscore):
// - a sink gets exactly each image of a frame, from version 5 streams of both codecs and from the
//   captures an earlier build wrote (test/capture/data: versions 3 and 4), and an image it declines
//   stays in the frame;
// - those earlier captures read back to the frames make_test_capture writes today (bridge_ok.vcap);
// - the messages frameMessages builds from a sink's images are byte for byte those it builds from the
//   frame's vectors (depth turned into metres and primitive ids masked in place);
// - an image of the wrong size is declined and the frame is reported by validateFrame.
#include "viper/capture/capture_stream.h"
#include "viper/ros/conversions/frame_conversions.h"

#include "../capture/test_capture_stream_frames.h"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <string>
#include <vector>

namespace viper {
namespace {

const std::string kCaptureToday = VIPER_TEST_CAPTURE_OK;  // make_test_capture, this build (version 5)
const std::string kCaptureV3 = VIPER_TEST_CAPTURE_V3;     // the same command, build 8bdc35f, zstd
const std::string kCaptureV4 = VIPER_TEST_CAPTURE_V4;     // the same frames, build 8bdc35f, LZ4

// A sink that keeps each image in storage of its own, or declines the images not in `take`.
class StoringSink : public CaptureImageSink {
 public:
  std::array<bool, 4> take{{true, true, true, true}};
  std::array<std::vector<char>, 4> stored;
  std::array<int, 4> calls{{0, 0, 0, 0}};
  uint64_t frame_number = ~0ull;

  void* imageStorage(CaptureImage image, const CaptureFrame& frame, size_t bytes) override {
    const int k = static_cast<int>(image);
    ++calls[k];
    frame_number = frame.number;
    if (!take[k]) return nullptr;
    stored[k].assign(bytes, '\x5a');  // any bytes: the reader overwrites every one
    return stored[k].data();
  }
};

template <typename T>
std::vector<char> bytesOf(const std::vector<T>& v) {
  const char* p = reinterpret_cast<const char*>(v.data());
  return std::vector<char>(p, p + v.size() * sizeof(T));
}

std::vector<char> imageBytes(const CaptureFrame& f, int k) {
  switch (k) {
    case 0: return bytesOf(f.color_rgb);
    case 1: return bytesOf(f.depth_window);
    case 2: return bytesOf(f.draw_ids);
    default: return bytesOf(f.primitive_ids);
  }
}

std::vector<CaptureFrame> readAll(const std::string& path) {
  CaptureReader reader(path);
  std::vector<CaptureFrame> frames;
  CaptureFrame frame;
  while (reader.next(frame) == CaptureReader::Status::kFrame) frames.push_back(frame);
  return frames;
}

// Reads `path` with a sink and without, side by side: the sink gets each image the plain read puts
// in the frame (those it declines stay in the frame), everything else is the same.
void expectTheSinkGetsEveryImage(const std::string& path, std::array<bool, 4> take) {
  CaptureReader plain(path), sunk(path);
  StoringSink sink;
  sink.take = take;
  sunk.setImageSink(&sink);
  CaptureFrame a, b;
  int frames = 0;
  while (plain.next(a) == CaptureReader::Status::kFrame) {
    SCOPED_TRACE(path + ": frame " + std::to_string(a.number));
    sink.calls = {{0, 0, 0, 0}};
    ASSERT_EQ(sunk.next(b), CaptureReader::Status::kFrame);
    EXPECT_EQ(sink.frame_number, a.number);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(sink.calls[k], 1) << "image " << k << " offered once";
      if (take[k]) {
        EXPECT_TRUE(imageBytes(b, k).empty()) << "image " << k << " left in the frame";
        EXPECT_TRUE(sink.stored[k] == imageBytes(a, k)) << "image " << k;
      } else {
        EXPECT_TRUE(imageBytes(b, k) == imageBytes(a, k)) << "image " << k;
      }
    }
    test::expectFrameEq(test::withoutImages(b), test::withoutImages(a));
    ++frames;
  }
  EXPECT_EQ(sunk.next(b), CaptureReader::Status::kEnd);
  EXPECT_GT(frames, 1);
}

TEST(CaptureImageSink, GetsExactlyEachImageOfEveryVersionAndCodec) {
  test::TempPath zstd("sink_zstd"), lz4("sink_lz4");
  test::writeStream(zstd.path, 4, 40, 30, CaptureCodec::kZstd);
  test::writeStream(lz4.path, 4, 40, 30, CaptureCodec::kLz4);
  for (const std::string& path : {zstd.path, lz4.path, kCaptureToday, kCaptureV3, kCaptureV4}) {
    expectTheSinkGetsEveryImage(path, {{true, true, true, true}});
    expectTheSinkGetsEveryImage(path, {{false, true, false, true}});
  }
}

TEST(CaptureImageSink, ReadsNothingWithoutImagesAndLeavesEmptyImagesAlone) {
  test::TempPath tmp("sink_without_images");
  {
    CaptureWriter writer(tmp.path, CaptureHeader());
    CaptureFrame empty = test::withoutImages(test::makeFrame(0, 8, 6));
    writer.write(empty);
    writer.write(test::makeFrame(1, 8, 6));
  }
  CaptureReader reader(tmp.path);
  StoringSink sink;
  reader.setImageSink(&sink);
  CaptureFrame frame;
  ASSERT_EQ(reader.next(frame), CaptureReader::Status::kFrame);
  EXPECT_EQ(sink.calls, (std::array<int, 4>{{0, 0, 0, 0}})) << "a frame without images offers none";
  ASSERT_EQ(reader.nextWithoutImages(frame), CaptureReader::Status::kFrame);
  EXPECT_EQ(sink.calls, (std::array<int, 4>{{0, 0, 0, 0}})) << "nextWithoutImages never calls the sink";
  EXPECT_EQ(reader.next(frame), CaptureReader::Status::kEnd);
}

TEST(CaptureImageSink, CapturesOfAnEarlierBuildReadAsTheFramesWrittenToday) {
  // make_test_capture's frames are computed on the CPU, the same on every run: the captures the
  // build of 8bdc35f wrote (format versions 3 and 4) hold the frames this build writes as version 5.
  EXPECT_EQ(CaptureReader(kCaptureV3).header().version, 3u);
  EXPECT_EQ(CaptureReader(kCaptureV4).header().version, 4u);
  EXPECT_EQ(CaptureReader(kCaptureV4).header().codec, CaptureCodec::kLz4);
  EXPECT_EQ(CaptureReader(kCaptureToday).header().version, kCaptureFormatVersion);
  const std::vector<CaptureFrame> today = readAll(kCaptureToday);
  ASSERT_EQ(today.size(), 8u);
  for (const std::string& path : {kCaptureV3, kCaptureV4}) {
    const std::vector<CaptureFrame> earlier = readAll(path);
    ASSERT_EQ(earlier.size(), today.size()) << path;
    for (size_t i = 0; i < today.size(); ++i) {
      SCOPED_TRACE(path + ": frame " + std::to_string(i));
      EXPECT_EQ(validateFrame(earlier[i]), "");
      test::expectFrameEq(earlier[i], today[i]);
      EXPECT_TRUE(encodeFramePayload(earlier[i]) == encodeFramePayload(today[i])) << "every byte";
    }
  }
}

void expectSameImage(const sensor_msgs::ImagePtr& a, const sensor_msgs::ImagePtr& b, const char* what) {
  ASSERT_TRUE(a && b) << what;
  EXPECT_EQ(a->header.stamp, b->header.stamp) << what;
  EXPECT_EQ(a->header.frame_id, b->header.frame_id) << what;
  EXPECT_EQ(a->width, b->width) << what;
  EXPECT_EQ(a->height, b->height) << what;
  EXPECT_EQ(a->encoding, b->encoding) << what;
  EXPECT_EQ(a->step, b->step) << what;
  EXPECT_EQ(a->is_bigendian, b->is_bigendian) << what;
  // Byte for byte: NaN depth compares equal here, and the metres must have the same bits.
  EXPECT_TRUE(a->data == b->data) << what;
}

TEST(FrameImageMessages, MakeTheMessagesTheFrameMakes) {
  for (const std::string& path : {kCaptureToday, kCaptureV3, kCaptureV4}) {
    CaptureReader plain(path), sunk(path);
    FrameImagePools plain_pools, sunk_pools;
    FrameImageMessages images(sunk_pools);
    sunk.setImageSink(&images);
    MeshStoreAccumulator plain_meshes, sunk_meshes;
    CaptureFrame a, b;
    int frames = 0, masked = 0, nan = 0;
    while (plain.next(a) == CaptureReader::Status::kFrame) {
      SCOPED_TRACE(path + ": frame " + std::to_string(a.number));
      images.clear();
      ASSERT_EQ(sunk.next(b), CaptureReader::Status::kFrame);
      for (CaptureImage k : {CaptureImage::kColor, CaptureImage::kDepth, CaptureImage::kDrawIds,
                             CaptureImage::kPrimitiveIds})
        ASSERT_TRUE(images.message(k)) << "image " << static_cast<int>(k) << " in a message";
      EXPECT_EQ(validateFrame(b, images.elsewhere()), "");
      std_msgs::Header header;
      header.stamp = ros::Time(1000 + a.time_s);
      header.frame_id = "camera";
      const FrameMessages x = frameMessages(a, header, plain_meshes, plain_pools);
      const FrameMessages y = frameMessages(b, header, sunk_meshes, sunk_pools, images);
      expectSameImage(x.color, y.color, "color");
      expectSameImage(x.depth, y.depth, "depth");
      expectSameImage(x.draw_ids, y.draw_ids, "draw_ids");
      expectSameImage(x.primitive_ids, y.primitive_ids, "primitive_ids");
      EXPECT_EQ(y.color->data.data(), images.message(CaptureImage::kColor)->data.data()) << "not copied";
      EXPECT_EQ(*x.camera_info, *y.camera_info);
      EXPECT_EQ(*x.draws, *y.draws);
      EXPECT_EQ(bool(x.mesh_store), bool(y.mesh_store));
      const auto* primitives = reinterpret_cast<const int32_t*>(y.primitive_ids->data.data());
      const auto* metres = reinterpret_cast<const float*>(y.depth->data.data());
      for (size_t i = 0; i < a.pixelCount(); ++i) {
        masked += primitives[i] == -1;
        nan += std::isnan(metres[i]);
      }
      ++frames;
    }
    EXPECT_EQ(frames, 8);
    EXPECT_GT(masked, 0) << "the frames have pixels of no draw (masked to -1)";
    EXPECT_LT(nan, frames * 96 * 64) << "and depth in metres";
  }
}

// Writes `frame` alone to a capture at `path` and reads it back with `images` as the sink.
CaptureFrame writeAndReadWithSink(const std::string& path, const CaptureFrame& frame, FrameImageMessages& images) {
  {
    CaptureWriter writer(path, CaptureHeader());
    writer.write(frame);
  }
  CaptureReader reader(path);
  reader.setImageSink(&images);
  CaptureFrame read;
  EXPECT_EQ(reader.next(read), CaptureReader::Status::kFrame);
  return read;
}

TEST(FrameImageMessages, DeclinesAnImageOfTheWrongSizeAndTheFrameIsReported) {
  test::TempPath tmp("sink_wrong_size");
  CaptureFrame frame = test::makeFrame(0, 16, 12);
  frame.depth_window.pop_back();
  FrameImagePools pools;
  FrameImageMessages images(pools);
  const CaptureFrame read = writeAndReadWithSink(tmp.path, frame, images);
  EXPECT_FALSE(images.message(CaptureImage::kDepth));
  EXPECT_TRUE(images.message(CaptureImage::kColor));
  EXPECT_EQ(read.depth_window.size(), frame.depth_window.size()) << "kept in the frame";
  const std::string problem = validateFrame(read, images.elsewhere());
  EXPECT_NE(problem.find("depth_window has 191 elements, expected 192"), std::string::npos) << problem;
  images.clear();
  for (CaptureImage k :
       {CaptureImage::kColor, CaptureImage::kDepth, CaptureImage::kDrawIds, CaptureImage::kPrimitiveIds})
    EXPECT_FALSE(images.message(k));
}

// With every image in its message, validateFrame leaves the draw ids' range to frameMessages, which
// checks it in its one pass over the ids (depth, primitive ids) and throws with validateFrame's words:
// the frame is dropped, not published.
TEST(FrameImageMessages, ADrawIdNamingNoDrawIsReportedByFrameMessages) {
  test::TempPath tmp("sink_bad_id");
  CaptureFrame frame = test::makeFrame(0, 40, 12);
  frame.draw_ids[3 * 40 + 37] = static_cast<uint32_t>(frame.draws.size() + 2);
  const std::string want = validateFrame(frame);
  ASSERT_NE(want.find("pixel (37, 3) has draw id"), std::string::npos) << want;
  FrameImagePools pools;
  FrameImageMessages images(pools);
  const CaptureFrame read = writeAndReadWithSink(tmp.path, frame, images);
  ASSERT_TRUE(images.elsewhere().draw_id_range_later);
  EXPECT_EQ(validateFrame(read, images.elsewhere()), "");
  MeshStoreAccumulator meshes;
  std_msgs::Header header;
  try {
    frameMessages(read, header, meshes, pools, images);
    ADD_FAILURE() << "frameMessages took a draw id that names no draw";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), want);
  }
  EXPECT_TRUE(meshes.store().meshes.empty()) << "the meshes of a dropped frame are not kept";
}

}  // namespace
}  // namespace viper
