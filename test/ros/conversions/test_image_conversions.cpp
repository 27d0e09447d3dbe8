// The one image check, and image messages <-> the package's pixel buffers, both ways.
#include "viper/ros/conversions/image_conversions.h"

#include "sample_header.h"

#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>

namespace viper {
namespace {

std_msgs::Header header() { return test::sampleHeader(); }

TEST(ImageConversions, BytesPerPixelOfTheEncodingsWeUse) {
  EXPECT_EQ(bytesPerPixel("mono8"), 1u);
  EXPECT_EQ(bytesPerPixel("rgb8"), 3u);
  EXPECT_EQ(bytesPerPixel("bgra8"), 4u);
  EXPECT_EQ(bytesPerPixel("32SC1"), 4u);
  EXPECT_EQ(bytesPerPixel("32FC1"), 4u);
  EXPECT_EQ(bytesPerPixel("32FC2"), 8u);
  EXPECT_EQ(bytesPerPixel("mono16"), 2u);
  EXPECT_EQ(bytesPerPixel("no_such_encoding"), 0u);
}

TEST(ImageConversions, CheckNamesWhatIsWrong) {
  const std::vector<int32_t> ids = {1, 2, 3, 4, 5, 6};
  const sensor_msgs::Image good = imageMsg(header(), 3, 2, "32SC1", 4, ids.data());
  EXPECT_EQ(checkImage(good, "32SC1"), "");
  EXPECT_EQ(checkImage(good, "32SC1", 3, 2), "");
  EXPECT_NE(checkImage(good, "mono8").find("encoding is '32SC1', expected mono8 (3x2)"), std::string::npos);
  EXPECT_NE(checkImage(good, "32SC1", 4, 2).find("size is 3x2, expected 4x2: sizes disagree"), std::string::npos);
  sensor_msgs::Image bad = good;
  bad.width = 0;
  EXPECT_NE(checkImage(bad, "32SC1").find("empty image"), std::string::npos);
  bad = good;
  bad.is_bigendian = 1;
  EXPECT_NE(checkImage(bad, "32SC1").find("big-endian"), std::string::npos);
  EXPECT_EQ(checkImage(bad, "32SC1", 0, 0, ImageLayout::kAnyStep), "");  // copied and swapped instead
  bad = good;
  bad.step = 16;
  bad.data.resize(32);
  EXPECT_NE(checkImage(bad, "32SC1").find("rows must not be padded"), std::string::npos);
  EXPECT_EQ(checkImage(bad, "32SC1", 0, 0, ImageLayout::kAnyStep), "");
  bad.step = 8;
  bad.data.resize(16);
  EXPECT_NE(checkImage(bad, "32SC1", 0, 0, ImageLayout::kAnyStep).find("step 8 is less than width * 4 = 12"),
            std::string::npos);
  bad = good;
  bad.data.pop_back();
  EXPECT_NE(checkImage(bad, "32SC1").find("data has 23 bytes, step * height is 24"), std::string::npos);
  // 8-bit data has no byte order.
  const std::vector<uint8_t> mono = {1, 2, 3, 4};
  sensor_msgs::Image big_mono = imageMsg(header(), 2, 2, "mono8", 1, mono.data());
  big_mono.is_bigendian = 1;
  EXPECT_EQ(checkImage(big_mono, "mono8"), "");
}

TEST(ImageConversions, Image8RoundTrip) {
  dataset::Image8 rgb;
  rgb.width = 2, rgb.height = 2, rgb.channels = 3;
  rgb.data = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const sensor_msgs::Image msg = toImageMsg(rgb, header());
  EXPECT_EQ(msg.encoding, "rgb8");
  EXPECT_EQ(msg.header.stamp, header().stamp);
  dataset::Image8 back;
  ASSERT_EQ(imageFromMsg(msg, "rgb8", back), "");
  EXPECT_EQ(back.width, 2u);
  EXPECT_EQ(back.channels, 3u);
  EXPECT_EQ(back.data, rgb.data);

  dataset::Image8 classes;
  classes.width = 3, classes.height = 1, classes.channels = 1;
  classes.data = {0, 7, 24};
  ASSERT_EQ(imageFromMsg(toImageMsg(classes, header()), "mono8", back), "");
  EXPECT_EQ(back.data, classes.data);
}

TEST(ImageConversions, PaddedBgrAndBigEndianMessagesAreCopiedIntoHostOrder) {
  // A 2x2 bgr8 image with rows padded to 8 bytes.
  sensor_msgs::Image bgr;
  bgr.width = 2, bgr.height = 2, bgr.encoding = "bgr8", bgr.step = 8;
  bgr.data = {3, 2, 1, 6, 5, 4, 0, 0, 9, 8, 7, 12, 11, 10, 0, 0};
  dataset::Image8 rgb;
  ASSERT_EQ(imageFromMsg(bgr, "rgb8", rgb), "");
  EXPECT_EQ(rgb.data, (std::vector<uint8_t>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}));

  // 32SC1 written big-endian by another machine.
  const std::vector<int32_t> ids = {1, -2, 70000};
  sensor_msgs::Image big = imageMsg(header(), 3, 1, "32SC1", 4, ids.data());
  big.is_bigendian = 1;
  for (size_t i = 0; i < 3; ++i) std::reverse(big.data.begin() + 4 * i, big.data.begin() + 4 * i + 4);
  std::vector<int32_t> back;
  ASSERT_EQ(int32FromMsg(big, back), "");
  EXPECT_EQ(back, ids);

  const std::vector<float> depth = {0.5f, NAN, 80.25f};
  std::vector<float> depth_back;
  ASSERT_EQ(float32FromMsg(imageMsg(header(), 3, 1, "32FC1", 4, depth.data()), depth_back), "");
  EXPECT_EQ(depth_back[0], 0.5f);
  EXPECT_TRUE(std::isnan(depth_back[1]));
  EXPECT_EQ(depth_back[2], 80.25f);
  EXPECT_NE(float32FromMsg(big, depth_back).find("expected 32FC1"), std::string::npos);
}

TEST(ImageConversions, SharedMessageHoldsTheSameBytes) {
  const std::vector<uint8_t> mono = {9, 8, 7, 6, 5, 4};
  const sensor_msgs::ImagePtr shared = imageMsgPtr(header(), 3, 2, "mono8", 1, mono.data());
  EXPECT_EQ(*shared, imageMsg(header(), 3, 2, "mono8", 1, mono.data()));
  EXPECT_EQ(shared->data, mono);
  EXPECT_EQ(shared->step, 3u);
}

}  // namespace
}  // namespace viper
