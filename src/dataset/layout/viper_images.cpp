#include "viper/dataset/viper_images.h"

#include "../formats/deflate_writers.h"
#include "../formats/jpeg_size.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <png.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace viper::dataset {
namespace {

// Largest side and size accepted from a file header: a damaged header must not make us allocate
// gigabytes (a 791-byte JPEG declaring 30000 x 30000 pixels asked for 2.7 GB before this limit).
constexpr uint32_t kMaxSide = 32768;
constexpr uint64_t kMaxPixels = uint64_t(1) << 27;  // e.g. 16384 x 8192; VIPER's frames have 2^21

// Empty if an image of this size may be read, else why not.
std::string sizeProblem(uint64_t width, uint64_t height) {
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide || width * height > kMaxPixels)
    return "declares " + std::to_string(width) + "x" + std::to_string(height) + " pixels (at most " +
           std::to_string(kMaxSide) + " a side and " + std::to_string(kMaxPixels) + " in all; damaged header?)";
  return {};
}

std::vector<uint8_t> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool endsWith(const std::string& s, const std::string& tail) {
  if (s.size() < tail.size()) return false;
  return std::equal(tail.rbegin(), tail.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
}

bool isJpegPath(const std::string& path) { return endsWith(path, ".jpg") || endsWith(path, ".jpeg"); }

// Whether `bytes` start with JPEG's start-of-image marker.
bool startsAsJpeg(const std::vector<uint8_t>& bytes) {
  return bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8;
}


void checkImage(const Image8& image, uint32_t channels, const char* what) {
  if (image.width == 0 || image.height == 0 || image.channels != channels ||
      image.data.size() != image.pixels() * channels)
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(channels) + " channel(s) of " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels, got " +
                                std::to_string(image.channels) + " channel(s) and " + std::to_string(image.data.size()) +
                                " bytes");
}

void checkView(const ImageView8& image, uint32_t channels, const char* what) {
  if (image.width == 0 || image.height == 0 || image.channels != channels || image.data == nullptr)
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(channels) + " channel(s) of " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels, got " +
                                std::to_string(image.channels) + " channel(s)" +
                                (image.data == nullptr ? " and no pixels" : ""));
}

// libpng reports errors through a callback that must not return; it long-jumps back to the
// setjmp in the caller. Everything the caller touches after setjmp lives in this context (in
// memory, not in registers), so its value is defined after the jump.
struct PngContext {
  const std::vector<uint8_t>* bytes = nullptr;
  size_t pos = 0;
  char error[256] = {0};
  Image8 image;
  std::vector<png_bytep> rows;
};

[[noreturn]] void pngError(png_structp png, png_const_charp message) {
  auto* ctx = static_cast<PngContext*>(png_get_error_ptr(png));
  if (ctx->error[0] == 0) std::snprintf(ctx->error, sizeof ctx->error, "%s", message);
  png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}  // e.g. odd color profiles: not our business

void pngRead(png_structp png, png_bytep out, size_t n) {
  auto* ctx = static_cast<PngContext*>(png_get_io_ptr(png));
  if (ctx->pos + n > ctx->bytes->size()) {
    std::snprintf(ctx->error, sizeof ctx->error, "file is truncated: %zu bytes, data needed up to byte %zu",
                  ctx->bytes->size(), ctx->pos + n);
    png_error(png, ctx->error);
  }
  std::memcpy(out, ctx->bytes->data() + ctx->pos, n);
  ctx->pos += n;
}

enum class PngKind { kColor, kClassIds, kInstances };

Image8 decodePng(const std::string& path, const std::vector<uint8_t>& bytes, PngKind kind) {
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0)
    throw std::runtime_error(path + ": not a PNG file (no PNG signature in its first 8 bytes)");
  PngContext ctx;
  ctx.bytes = &bytes;
  ctx.pos = 8;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, pngError, pngWarning);
  if (png == nullptr) throw std::runtime_error(path + ": libpng could not start");
  png_infop info = png_create_info_struct(png);
  std::string rejected;
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error(path + ": corrupt PNG: " + (ctx.error[0] ? ctx.error : "libpng could not start"));
  }
  png_set_read_fn(png, &ctx, pngRead);
  png_set_sig_bytes(png, 8);
  png_set_user_limits(png, kMaxSide, kMaxSide);
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int depth = 0, color = 0;
  png_get_IHDR(png, info, &width, &height, &depth, &color, nullptr, nullptr, nullptr);
  const char* color_name = color == PNG_COLOR_TYPE_GRAY         ? "gray"
                           : color == PNG_COLOR_TYPE_GRAY_ALPHA ? "gray+alpha"
                           : color == PNG_COLOR_TYPE_PALETTE    ? "palette"
                           : color == PNG_COLOR_TYPE_RGB        ? "RGB"
                                                                : "RGBA";
  const std::string size_problem = sizeProblem(width, height);
  if (!size_problem.empty()) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error(path + ": PNG " + size_problem);
  }
  uint32_t channels = 3;
  switch (kind) {
    case PngKind::kClassIds:
      channels = 1;
      if ((color != PNG_COLOR_TYPE_PALETTE && color != PNG_COLOR_TYPE_GRAY) || depth > 8)
        rejected = std::string("is a ") + std::to_string(depth) + "-bit " + color_name +
                   " PNG; class ids need one 8-bit channel (palette or gray)";
      else
        png_set_packing(png);  // 1/2/4-bit indices or gray values to one byte each, not rescaled
      break;
    case PngKind::kInstances:
      if ((color != PNG_COLOR_TYPE_RGB && color != PNG_COLOR_TYPE_RGB_ALPHA) || depth != 8)
        rejected = std::string("is a ") + std::to_string(depth) + "-bit " + color_name +
                   " PNG; instance images are 8-bit RGB (R = class, 256 * G + B = instance)";
      else if (color == PNG_COLOR_TYPE_RGB_ALPHA)
        png_set_strip_alpha(png);
      break;
    case PngKind::kColor:
      png_set_expand(png);
      if (depth == 16) png_set_strip_16(png);
      png_set_strip_alpha(png);
      if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
      break;
  }
  if (!rejected.empty()) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error(path + ": " + rejected);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  if (row_bytes != static_cast<size_t>(width) * channels) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw std::runtime_error(path + ": unexpected PNG row size " + std::to_string(row_bytes) + " for " +
                             std::to_string(width) + " pixels of " + std::to_string(channels) + " channel(s)");
  }
  ctx.image.width = width;
  ctx.image.height = height;
  ctx.image.channels = channels;
  ctx.image.data.resize(row_bytes * height);
  ctx.rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) ctx.rows[y] = ctx.image.data.data() + y * row_bytes;
  png_read_image(png, ctx.rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return std::move(ctx.image);
}

void encodePng(const std::string& path, const ImageView8& image, detail::PngColor color, const ClassPalette* palette,
               const ImageWriteOptions& options) {
  if (options.png_compression_level < 0 || options.png_compression_level > 9)
    throw std::invalid_argument("PNG compression level must be 0..9, got " +
                                std::to_string(options.png_compression_level));
  ClassPalette full;
  if (palette != nullptr) {
    full.assign(256, {{0, 0, 0}});
    std::copy_n(palette->begin(), std::min<size_t>(256, palette->size()), full.begin());
  }
  const int level = options.png_compression_level;
  detail::writeFileAtomically(path, detail::pngBytes(image.data, image.width, image.height, color, full,
                                                     level),
                              "PNG", options.digests);
}

Image8 decodeJpeg(const std::string& path, const std::vector<uint8_t>& bytes) {
  if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8)
    throw std::runtime_error(path + ": not a JPEG file (no start-of-image marker)");
  // libjpeg fills a truncated file with gray and only warns; the end-of-image marker tells.
  const size_t tail = std::min<size_t>(bytes.size(), 64);
  bool has_end = false;
  for (size_t i = bytes.size() - tail; i + 1 < bytes.size(); ++i)
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xD9) has_end = true;
  if (!has_end) throw std::runtime_error(path + ": truncated JPEG (no end-of-image marker)");
  JpegSize size;
  try {
    size = readJpegSize(bytes.data(), bytes.size());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": corrupt JPEG: " + e.what());
  }
  const std::string size_problem = sizeProblem(size.width, size.height);
  if (!size_problem.empty()) throw std::runtime_error(path + ": JPEG " + size_problem);
  cv::Mat bgr;
  try {
    bgr = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<uint8_t*>(bytes.data())),
                       cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": corrupt JPEG: " + e.what());
  }
  if (bgr.empty() || bgr.type() != CV_8UC3) throw std::runtime_error(path + ": corrupt JPEG (cannot be decoded)");
  Image8 out;
  out.width = static_cast<uint32_t>(bgr.cols);
  out.height = static_cast<uint32_t>(bgr.rows);
  out.channels = 3;
  out.data.resize(out.pixels() * 3);
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, out.data.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return out;
}

void encodeJpeg(const std::string& path, const ImageView8& rgb, int quality, FileDigests* digests) {
  if (quality < 0 || quality > 100) throw std::invalid_argument("JPEG quality must be 0..100");
  cv::Mat src(static_cast<int>(rgb.height), static_cast<int>(rgb.width), CV_8UC3, const_cast<uint8_t*>(rgb.data));
  cv::Mat bgr;
  cv::cvtColor(src, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality}))
    throw std::runtime_error(path + ": cannot encode JPEG");
  detail::writeFileAtomically(path, bytes, "JPEG", digests);
}

// A PNG that must be lossless (`what`: "class ids" or "instance images"): a JPEG is refused.
Image8 readLosslessPng(const std::string& path, PngKind kind, const char* what) {
  const std::vector<uint8_t> bytes = readFile(path);
  if (startsAsJpeg(bytes)) throw std::runtime_error(path + ": is a JPEG; " + what + " must be a lossless PNG");
  return decodePng(path, bytes, kind);
}

}  // namespace

Image8 readViperColorImage(const std::string& path) {
  const std::vector<uint8_t> bytes = readFile(path);
  if (startsAsJpeg(bytes) || isJpegPath(path)) return decodeJpeg(path, bytes);
  return decodePng(path, bytes, PngKind::kColor);
}

void writeViperColorImage(const std::string& path, const Image8& rgb, const ImageWriteOptions& options) {
  checkImage(rgb, 3, "writeViperColorImage");
  writeViperColorImage(path, ImageView8(rgb), options);
}

void writeViperColorImage(const std::string& path, const ImageView8& rgb, const ImageWriteOptions& options) {
  checkView(rgb, 3, "writeViperColorImage");
  if (isJpegPath(path)) encodeJpeg(path, rgb, options.jpeg_quality, options.digests);
  else encodePng(path, rgb, detail::PngColor::kRgb, nullptr, options);
}

Image8 readViperClassImage(const std::string& path) {
  return readLosslessPng(path, PngKind::kClassIds, "class ids");
}

void writeViperClassImage(const std::string& path, const Image8& class_ids, const ClassPalette& palette,
                          const ImageWriteOptions& options) {
  checkImage(class_ids, 1, "writeViperClassImage");
  writeViperClassImage(path, ImageView8(class_ids), palette, options);
}

void writeViperClassImage(const std::string& path, const ImageView8& class_ids, const ClassPalette& palette,
                          const ImageWriteOptions& options) {
  checkView(class_ids, 1, "writeViperClassImage");
  if (palette.empty()) encodePng(path, class_ids, detail::PngColor::kGray, nullptr, options);
  else encodePng(path, class_ids, detail::PngColor::kPalette, &palette, options);
}

Image8 readViperInstanceImage(const std::string& path) {
  return readLosslessPng(path, PngKind::kInstances, "instance images");
}

void writeViperInstanceImage(const std::string& path, const Image8& instances, const ImageWriteOptions& options) {
  checkImage(instances, 3, "writeViperInstanceImage");
  writeViperInstanceImage(path, ImageView8(instances), options);
}

void writeViperInstanceImage(const std::string& path, const ImageView8& instances, const ImageWriteOptions& options) {
  checkView(instances, 3, "writeViperInstanceImage");
  encodePng(path, instances, detail::PngColor::kRgb, nullptr, options);
}

std::vector<int32_t> viperInstanceIds(const Image8& instances) {
  checkImage(instances, 3, "viperInstanceIds");
  std::vector<int32_t> ids(instances.pixels());
  const uint8_t* p = instances.data.data();
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = 256 * p[3 * i + 1] + p[3 * i + 2];
  return ids;
}

std::vector<uint8_t> viperInstanceClasses(const Image8& instances) {
  checkImage(instances, 3, "viperInstanceClasses");
  std::vector<uint8_t> classes(instances.pixels());
  for (size_t i = 0; i < classes.size(); ++i) classes[i] = instances.data[3 * i];
  return classes;
}

}  // namespace viper::dataset
