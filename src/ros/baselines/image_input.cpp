#include "viper/ros/baselines/image_input.h"

#include "viper/ros/conversions/image_conversions.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

namespace viper {
namespace {

/// The message's pixels in `target` (mono8 or rgb8), converted by cv_bridge; the encodings the
/// baselines take (8-bit colour or gray) and the message's size and step are checked first, since
/// cv_bridge reads the buffer as the message describes it.
bool convertImage(const sensor_msgs::Image& msg, const std::string& target, cv::Mat& out, std::string& error) {
  namespace enc = sensor_msgs::image_encodings;
  if (msg.encoding != enc::RGB8 && msg.encoding != enc::BGR8 && msg.encoding != enc::RGBA8 &&
      msg.encoding != enc::BGRA8 && msg.encoding != enc::MONO8) {
    error = "unsupported encoding '" + msg.encoding + "' (want rgb8, bgr8, rgba8, bgra8 or mono8)";
    return false;
  }
  error = checkImage(msg, msg.encoding, 0, 0, ImageLayout::kAnyStep);
  if (!error.empty()) return false;
  try {
    out = cv_bridge::toCvCopy(msg, target)->image;
  } catch (const cv_bridge::Exception& e) {
    error = std::string("cv_bridge: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace

bool grayFromImage(const sensor_msgs::Image& msg, cv::Mat& gray, std::string& error) {
  return convertImage(msg, sensor_msgs::image_encodings::MONO8, gray, error);
}

bool rgbFromImage(const sensor_msgs::Image& msg, cv::Mat& rgb, std::string& error) {
  return convertImage(msg, sensor_msgs::image_encodings::RGB8, rgb, error);
}

}  // namespace viper
