#include "viper/ros/conversions/image_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cstring>

namespace viper {
namespace {

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

bool hostBigEndian() { return __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__; }

// A one-channel image of 4-byte words, any step, either byte order.
template <typename Word>
std::string wordsFromMsg(const sensor_msgs::Image& msg, const std::string& encoding, std::vector<Word>& out) {
  static_assert(sizeof(Word) == 4, "4-byte words");
  const std::string problem = checkImage(msg, encoding, 0, 0, ImageLayout::kAnyStep);
  if (!problem.empty()) return problem;
  out.resize(static_cast<size_t>(msg.width) * msg.height);
  copyImageRows(msg, 4, reinterpret_cast<uint8_t*>(out.data()));
  return "";
}

// Bytes of one channel value, whose order matters: 1 for 8-bit encodings.
size_t channelBytes(const std::string& encoding) {
  try {
    return static_cast<size_t>(sensor_msgs::image_encodings::bitDepth(encoding)) / 8;
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

size_t bytesPerPixel(const std::string& encoding) {
  namespace enc = sensor_msgs::image_encodings;
  try {
    const int bits = enc::bitDepth(encoding) * enc::numChannels(encoding);
    return bits > 0 && bits % 8 == 0 ? static_cast<size_t>(bits / 8) : 0;
  } catch (const std::exception&) {  // an encoding image_encodings does not know
    return 0;
  }
}

std::string checkImage(const sensor_msgs::Image& image, const std::string& encoding, uint32_t width, uint32_t height,
                       ImageLayout layout) {
  const std::string size = sizeText(image.width, image.height);
  if (image.encoding != encoding) return "encoding is '" + image.encoding + "', expected " + encoding + " (" + size + ")";
  if (image.width == 0 || image.height == 0) return "size is " + size + ": empty image";
  if (width != 0 && (image.width != width || image.height != height))
    return "size is " + size + ", expected " + sizeText(width, height) + ": sizes disagree";
  const size_t bpp = bytesPerPixel(encoding);
  const size_t row = static_cast<size_t>(image.width) * bpp;
  if (bpp == 0) return "encoding " + encoding + " has no known pixel size";
  if (layout == ImageLayout::kPacked) {
    if (image.is_bigendian && channelBytes(encoding) > 1 && !hostBigEndian())
      return "big-endian " + encoding + " data is not supported";
    if (image.step != row)
      return "step " + std::to_string(image.step) + " for " + size + " " + encoding + ", expected " +
             std::to_string(row) + " (rows must not be padded)";
  } else if (image.step < row) {
    return "step " + std::to_string(image.step) + " is less than width * " + std::to_string(bpp) + " = " +
           std::to_string(row);
  }
  if (image.data.size() != static_cast<size_t>(image.step) * image.height)
    return "data has " + std::to_string(image.data.size()) + " bytes, step * height is " +
           std::to_string(static_cast<size_t>(image.step) * image.height) + ": sizes disagree";
  return "";
}

void copyImageRows(const sensor_msgs::Image& image, size_t word_bytes, uint8_t* dst) {
  const size_t row = static_cast<size_t>(image.width) * bytesPerPixel(image.encoding);
  if (image.step == row) {
    std::memcpy(dst, image.data.data(), row * image.height);
  } else {
    for (uint32_t y = 0; y < image.height; ++y) std::memcpy(dst + y * row, image.data.data() + y * image.step, row);
  }
  if (word_bytes > 1 && static_cast<bool>(image.is_bigendian) != hostBigEndian()) {
    const size_t n = row * image.height;
    for (size_t i = 0; i + word_bytes <= n; i += word_bytes) std::reverse(dst + i, dst + i + word_bytes);
  }
}

namespace {

// Header, size, encoding and step of an image message (its data untouched).
void setImageFields(const std_msgs::Header& header, uint32_t width, uint32_t height, const std::string& encoding,
                    uint32_t bytes_per_pixel, sensor_msgs::Image& m) {
  m.header = header;
  m.width = width;
  m.height = height;
  m.encoding = encoding;
  m.is_bigendian = 0;
  m.step = width * bytes_per_pixel;
}

}  // namespace

sensor_msgs::Image imageMsg(const std_msgs::Header& header, uint32_t width, uint32_t height,
                            const std::string& encoding, uint32_t bytes_per_pixel, const void* data) {
  sensor_msgs::Image m;
  setImageFields(header, width, height, encoding, bytes_per_pixel, m);
  // assign, not resize + memcpy: the bytes are written once, not zeroed first.
  const auto* bytes = static_cast<const uint8_t*>(data);
  m.data.assign(bytes, bytes + static_cast<size_t>(m.step) * height);
  return m;
}

sensor_msgs::ImagePtr imageMsgPtr(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                  const std::string& encoding, uint32_t bytes_per_pixel, const void* data) {
  return boost::make_shared<sensor_msgs::Image>(imageMsg(header, width, height, encoding, bytes_per_pixel, data));
}

void shapeImageMsg(const std_msgs::Header& header, uint32_t width, uint32_t height, const std::string& encoding,
                   uint32_t bytes_per_pixel, sensor_msgs::Image& m) {
  setImageFields(header, width, height, encoding, bytes_per_pixel, m);
  m.data.resize(static_cast<size_t>(m.step) * height);
}

sensor_msgs::ImagePtr newImageMsgPtr(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                     const std::string& encoding, uint32_t bytes_per_pixel) {
  auto m = boost::make_shared<sensor_msgs::Image>();
  shapeImageMsg(header, width, height, encoding, bytes_per_pixel, *m);
  return m;
}

sensor_msgs::Image toImageMsg(const dataset::Image8& image, const std_msgs::Header& header,
                              const std::string& encoding) {
  const std::string e = !encoding.empty() ? encoding : image.channels == 3 ? "rgb8" : "mono8";
  return imageMsg(header, image.width, image.height, e, image.channels, image.data.data());
}

std::string imageFromMsg(const sensor_msgs::Image& msg, const std::string& encoding, dataset::Image8& out) {
  const bool bgr = encoding == "rgb8" && msg.encoding == "bgr8";
  const std::string problem = checkImage(msg, bgr ? "bgr8" : encoding, 0, 0, ImageLayout::kAnyStep);
  if (!problem.empty()) return problem;
  out.width = msg.width, out.height = msg.height;
  out.channels = static_cast<uint32_t>(bytesPerPixel(encoding));
  out.data.resize(out.pixels() * out.channels);
  copyImageRows(msg, 1, out.data.data());
  if (bgr)
    for (size_t i = 0; i < out.pixels(); ++i) std::swap(out.data[3 * i], out.data[3 * i + 2]);
  return "";
}

std::string int32FromMsg(const sensor_msgs::Image& msg, std::vector<int32_t>& out) {
  return wordsFromMsg(msg, sensor_msgs::image_encodings::TYPE_32SC1, out);
}

std::string float32FromMsg(const sensor_msgs::Image& msg, std::vector<float>& out) {
  return wordsFromMsg(msg, sensor_msgs::image_encodings::TYPE_32FC1, out);
}

}  // namespace viper
