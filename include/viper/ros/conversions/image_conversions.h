// Image messages: the one check of an image message, and copies between messages and the
// package's pixel buffers. Part of the converter between messages and core types
// (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include "viper/dataset/viper_images.h"

#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// Bytes per pixel of an image encoding (any of sensor_msgs::image_encodings with a known bit depth
/// and channel count: rgb8 3, mono8 1, 32SC1 4, 32FC1 4, 32FC2 8, ...); 0 for any other.
size_t bytesPerPixel(const std::string& encoding);

/// How an image's memory may be laid out.
enum class ImageLayout {
  /// Rows without padding (step = width * bytes per pixel), little-endian words: what the
  /// package's nodes publish, read in place.
  kPacked,
  /// Any step of at least a row, either byte order: what a message from elsewhere may hold, read
  /// by copying (copyImageRows).
  kAnyStep,
};

/// The one check of an image message before its bytes are read: encoding `encoding`, not empty,
/// width x height pixels (0 x 0: any size), rows and byte order as `layout` allows, and exactly
/// step * height bytes of data. Returns "" if the image is fine, else what is wrong, in words that
/// name the encodings and sizes involved (for a throttled error naming the topic).
std::string checkImage(const sensor_msgs::Image& image, const std::string& encoding, uint32_t width = 0,
                       uint32_t height = 0, ImageLayout layout = ImageLayout::kPacked);

/// Copies the pixels of an image that passed checkImage into `dst` (width * height * bytes per
/// pixel bytes), dropping row padding and swapping words of `word_bytes` (2, 4 or 8; 1 = none)
/// into the host's byte order.
void copyImageRows(const sensor_msgs::Image& image, size_t word_bytes, uint8_t* dst);

/// An image message of `width` x `height` pixels of `bytes_per_pixel` bytes copied from `data`
/// (little-endian, unpadded rows).
sensor_msgs::Image imageMsg(const std_msgs::Header& header, uint32_t width, uint32_t height,
                            const std::string& encoding, uint32_t bytes_per_pixel, const void* data);
/// The same, shared: what the nodelets publish, so that subscribers in the same manager get the
/// message itself (zero-copy) instead of a serialised copy of it.
sensor_msgs::ImagePtr imageMsgPtr(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                  const std::string& encoding, uint32_t bytes_per_pixel, const void* data);
/// An image message of that size whose pixels the caller writes (`data` is sized, zeroed): images
/// computed straight into the message that carries them, not copied into it.
void shapeImageMsg(const std_msgs::Header& header, uint32_t width, uint32_t height, const std::string& encoding,
                   uint32_t bytes_per_pixel, sensor_msgs::Image& m);
sensor_msgs::ImagePtr newImageMsgPtr(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                     const std::string& encoding, uint32_t bytes_per_pixel);

/// An 8-bit image (1 channel: mono8, 3: rgb8) as a message; `encoding` overrides the default.
sensor_msgs::Image toImageMsg(const dataset::Image8& image, const std_msgs::Header& header,
                              const std::string& encoding = "");
/// An 8-bit image message into `out`: `encoding` is rgb8 (bgr8 accepted and swapped) or mono8; any
/// step. Returns "" or what is wrong (checkImage).
std::string imageFromMsg(const sensor_msgs::Image& msg, const std::string& encoding, dataset::Image8& out);
/// A 32SC1 image (draw ids, instance ids), any step, either byte order. Returns "" or what is wrong.
std::string int32FromMsg(const sensor_msgs::Image& msg, std::vector<int32_t>& out);
/// A 32FC1 image (depth in metres), any step, either byte order. Returns "" or what is wrong.
std::string float32FromMsg(const sensor_msgs::Image& msg, std::vector<float>& out);

}  // namespace viper
