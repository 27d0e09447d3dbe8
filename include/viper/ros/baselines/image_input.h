// The camera image as the baselines read it: any 8-bit colour or gray encoding, checked, converted
// to the one layout each method works on.
#pragma once

#include <opencv2/core.hpp>
#include <sensor_msgs/Image.h>

#include <string>

namespace viper {

/// Gray (mono8, own copy) of an image message: rgb8, bgr8, rgba8, bgra8 or mono8. Returns false and
/// says why in `error` (unsupported encoding, zero size, step or data too short for the size).
bool grayFromImage(const sensor_msgs::Image& msg, cv::Mat& gray, std::string& error);

/// RGB (CV_8UC3, own copy) of an image message: the same encodings and checks as grayFromImage.
bool rgbFromImage(const sensor_msgs::Image& msg, cv::Mat& rgb, std::string& error);

}  // namespace viper
