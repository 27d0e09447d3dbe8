// Image files of VIPER's release layout: camera images (`img`, PNG or JPEG), class id images
// (`cls`, 8-bit single-channel PNG, palette or grayscale) and instance images (`inst`, RGB PNG with
// R = class id and instance id = 256 * G + B). PNG through libpng, JPEG through OpenCV's
// imgcodecs. Details: docs/viper_layout.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

class FileDigests;

/// An 8-bit image: `channels` bytes per pixel, rows from the top, no padding.
struct Image8 {
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t channels = 0;       ///< 1 (class ids) or 3 (RGB, red first)
  std::vector<uint8_t> data;   ///< width * height * channels bytes

  size_t pixels() const { return static_cast<size_t>(width) * height; }
};

/// An 8-bit image's pixels wherever they are (an Image8's, a message's): `channels` bytes per
/// pixel, rows from the top, no padding.
struct ImageView8 {
  const uint8_t* data = nullptr;
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t channels = 0;

  ImageView8() = default;
  ImageView8(const uint8_t* data, uint32_t width, uint32_t height, uint32_t channels)
      : data(data), width(width), height(height), channels(channels) {}
  /// The pixels of `image` (which must outlive the view).
  ImageView8(const Image8& image)  // NOLINT: an image is a view of itself
      : data(image.data.data()), width(image.width), height(image.height), channels(image.channels) {}
  size_t pixels() const { return static_cast<size_t>(width) * height; }
};

/// How image files are written.
struct ImageWriteOptions {
  /// Deflate level of PNG files, 0 (stored) .. 9: 1 is ISA-L's igzip (fastest), 2..9 libdeflate's
  /// levels (smaller, slower).
  int png_compression_level = 1;
  /// JPEG quality 0..100 for `img` files written as .jpg / .jpeg.
  int jpeg_quality = 95;
  /// When set, each file's SHA-256 is recorded there as it is written (from the bytes in memory).
  FileDigests* digests = nullptr;
};

/// A class color per class id (index), for the palette of `cls` files.
using ClassPalette = std::vector<std::array<uint8_t, 3>>;

/// Reads a camera image (`img`): a PNG of any color type and bit depth (palette and gray are
/// expanded, alpha dropped, 16 bits reduced to 8) or a JPEG (.jpg, .jpeg). Returns 3 channels,
/// RGB. Throws std::runtime_error starting with `path` if the file is missing, is neither PNG nor
/// JPEG, or is truncated or corrupt (libpng's or OpenCV's reason is included). Every reader here
/// refuses, from the file's header and before decoding, an image over 32768 pixels a side or 2^27
/// pixels in all (a damaged header must not make it allocate gigabytes).
Image8 readViperColorImage(const std::string& path);

/// Writes an RGB image (3 channels) as PNG, or as JPEG when `path` ends in .jpg / .jpeg (lossy).
/// The file is written beside `path` under a temporary name and renamed, so readers never see half
/// a file. Throws std::invalid_argument if `rgb` is not 3 channels of width * height pixels (both
/// non-zero), std::runtime_error naming `path` if it cannot be written.
void writeViperColorImage(const std::string& path, const Image8& rgb,
                          const ImageWriteOptions& options = ImageWriteOptions());
/// The same from pixels wherever they are (`rgb.data` not null, 3 channels, both sizes non-zero).
void writeViperColorImage(const std::string& path, const ImageView8& rgb,
                          const ImageWriteOptions& options = ImageWriteOptions());

/// Reads a class id image (`cls`): a PNG with one 8-bit (or 1/2/4-bit) channel, either palette
/// (the palette indices are the class ids; the palette colors are ignored) or grayscale (the gray
/// values are the ids, never rescaled). Returns 1 channel. Throws std::runtime_error starting with
/// `path` for a missing, truncated or corrupt file, a JPEG, or a PNG with color channels, alpha or
/// 16 bits (which cannot hold class ids as VIPER writes them).
Image8 readViperClassImage(const std::string& path);

/// Writes class ids (1 channel) as an 8-bit PNG: indexed, with `palette` as its color table (class
/// colors, so viewers show the classes; ids beyond the palette get black), or grayscale when
/// `palette` is empty. Either way every reader that takes palette indices or gray values gets the
/// ids back. Same temporary-file rule and throws as writeViperColorImage.
void writeViperClassImage(const std::string& path, const Image8& class_ids, const ClassPalette& palette,
                          const ImageWriteOptions& options = ImageWriteOptions());
/// The same from pixels wherever they are (1 channel).
void writeViperClassImage(const std::string& path, const ImageView8& class_ids, const ClassPalette& palette,
                          const ImageWriteOptions& options = ImageWriteOptions());

/// Reads an instance image (`inst`): an 8-bit RGB PNG (RGBA: alpha dropped). Returns 3 channels.
/// Throws std::runtime_error starting with `path` for a missing, truncated or corrupt file, or a
/// PNG that is not 8-bit RGB(A) (palette, gray or 16-bit images cannot be VIPER instance images).
Image8 readViperInstanceImage(const std::string& path);

/// Writes an instance image (3 channels, R = class id, 256 * G + B = instance id) as an 8-bit RGB
/// PNG. Same temporary-file rule and throws as writeViperColorImage.
void writeViperInstanceImage(const std::string& path, const Image8& instances,
                             const ImageWriteOptions& options = ImageWriteOptions());
/// The same from pixels wherever they are (3 channels).
void writeViperInstanceImage(const std::string& path, const ImageView8& instances,
                             const ImageWriteOptions& options = ImageWriteOptions());

/// Instance ids of an instance image: 256 * G + B per pixel (0 = no instance). Throws
/// std::invalid_argument if `instances` is not 3 channels of width * height pixels.
std::vector<int32_t> viperInstanceIds(const Image8& instances);

/// Class ids of an instance image: its R channel. Same throws as viperInstanceIds.
std::vector<uint8_t> viperInstanceClasses(const Image8& instances);

}  // namespace viper::dataset
