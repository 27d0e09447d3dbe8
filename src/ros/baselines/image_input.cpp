#include "viper/ros/baselines/image_input.h"

#include "viper/ros/conversions/image_conversions.h"

#include <opencv2/imgproc.hpp>
#include <sensor_msgs/image_encodings.h>

namespace viper {
namespace {

/// The message's pixels converted by the cvtColor code its encoding needs to reach `gray` or RGB.
bool convertImage(const sensor_msgs::Image& msg, bool gray, cv::Mat& out, std::string& error) {
  namespace enc = sensor_msgs::image_encodings;
  int channels = 0, code = -1;
  if (msg.encoding == enc::RGB8) channels = 3, code = gray ? cv::COLOR_RGB2GRAY : -1;
  else if (msg.encoding == enc::BGR8) channels = 3, code = gray ? cv::COLOR_BGR2GRAY : cv::COLOR_BGR2RGB;
  else if (msg.encoding == enc::RGBA8) channels = 4, code = gray ? cv::COLOR_RGBA2GRAY : cv::COLOR_RGBA2RGB;
  else if (msg.encoding == enc::BGRA8) channels = 4, code = gray ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGRA2RGB;
  else if (msg.encoding == enc::MONO8) channels = 1, code = gray ? -1 : cv::COLOR_GRAY2RGB;
  else {
    error = "unsupported encoding '" + msg.encoding + "' (want rgb8, bgr8, rgba8, bgra8 or mono8)";
    return false;
  }
  // Checked here because a Mat over a short buffer would read past its end.
  error = checkImage(msg, msg.encoding, 0, 0, ImageLayout::kAnyStep);
  if (!error.empty()) return false;
  const cv::Mat view(msg.height, msg.width, CV_8UC(channels), const_cast<uint8_t*>(msg.data.data()), msg.step);
  if (code < 0) view.copyTo(out);
  else cv::cvtColor(view, out, code);
  return true;
}

}  // namespace

bool grayFromImage(const sensor_msgs::Image& msg, cv::Mat& gray, std::string& error) {
  return convertImage(msg, true, gray, error);
}

bool rgbFromImage(const sensor_msgs::Image& msg, cv::Mat& rgb, std::string& error) {
  return convertImage(msg, false, rgb, error);
}

}  // namespace viper
