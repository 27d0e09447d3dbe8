// The baselines' camera input (image_input.h, through cv_bridge): every 8-bit encoding they take
// gives the gray and RGB images OpenCV's own conversions give; bad messages are refused with the
// reason, never read past their data.
#include "viper/ros/baselines/image_input.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <sensor_msgs/image_encodings.h>

#include <string>

namespace viper {
namespace {

// A 7x5 image with distinct channels in `encoding`, padded rows (step > width * channels).
sensor_msgs::Image message(const std::string& encoding, int channels) {
  sensor_msgs::Image m;
  m.encoding = encoding;
  m.width = 7, m.height = 5;
  m.step = 7 * channels + 3;
  m.data.assign(m.step * m.height, 0);
  for (uint32_t y = 0; y < m.height; ++y)
    for (uint32_t x = 0; x < m.width; ++x)
      for (int c = 0; c < channels; ++c) m.data[y * m.step + x * channels + c] = static_cast<uint8_t>(17 * x + 29 * y + 61 * c);
  return m;
}

TEST(ImageInput, EveryEncodingGivesOpenCVsGrayAndRgb) {
  struct Case {
    const char* encoding;
    int channels;
    int to_rgb, to_gray;  // cvtColor codes (-1: the pixels as they are)
  };
  namespace enc = sensor_msgs::image_encodings;
  for (const Case& c : {Case{"rgb8", 3, -1, cv::COLOR_RGB2GRAY}, Case{"bgr8", 3, cv::COLOR_BGR2RGB, cv::COLOR_BGR2GRAY},
                        Case{"rgba8", 4, cv::COLOR_RGBA2RGB, cv::COLOR_RGBA2GRAY},
                        Case{"bgra8", 4, cv::COLOR_BGRA2RGB, cv::COLOR_BGRA2GRAY}, Case{"mono8", 1, cv::COLOR_GRAY2RGB, -1}}) {
    SCOPED_TRACE(c.encoding);
    const sensor_msgs::Image m = message(c.encoding, c.channels);
    const cv::Mat view(m.height, m.width, CV_8UC(c.channels), const_cast<uint8_t*>(m.data.data()), m.step);
    cv::Mat want_rgb, want_gray, rgb, gray;
    if (c.to_rgb < 0) view.copyTo(want_rgb);
    else cv::cvtColor(view, want_rgb, c.to_rgb);
    if (c.to_gray < 0) view.copyTo(want_gray);
    else cv::cvtColor(view, want_gray, c.to_gray);
    std::string error;
    ASSERT_TRUE(rgbFromImage(m, rgb, error)) << error;
    ASSERT_TRUE(grayFromImage(m, gray, error)) << error;
    ASSERT_EQ(rgb.type(), CV_8UC3);
    ASSERT_EQ(gray.type(), CV_8UC1);
    EXPECT_EQ(cv::norm(rgb, want_rgb, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(gray, want_gray, cv::NORM_INF), 0.0);
  }
}

TEST(ImageInput, BadMessagesAreRefusedWithTheReason) {
  std::string error;
  cv::Mat out;
  sensor_msgs::Image m = message("rgb16", 6);
  EXPECT_FALSE(rgbFromImage(m, out, error));
  EXPECT_NE(error.find("unsupported encoding 'rgb16'"), std::string::npos) << error;
  m = message("bgr8", 3);
  m.data.resize(m.data.size() - 10);  // shorter than height * step
  EXPECT_FALSE(grayFromImage(m, out, error));
  EXPECT_FALSE(error.empty());
  m = message("mono8", 1);
  m.step = 3;  // less than a row
  EXPECT_FALSE(rgbFromImage(m, out, error));
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace viper
