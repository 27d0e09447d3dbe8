#include "pixel_transfer.h"

namespace viper {
namespace capture {

namespace {

// Compatibility-profile and extension enums that the core header lacks.
constexpr GLenum kColorIndex = 0x1900, kLuminance = 0x1909, kLuminanceAlpha = 0x190A, kBitmap = 0x1A00;
constexpr GLenum kAbgrExt = 0x8000;
constexpr GLenum kAlphaInteger = 0x8D97, kLuminanceInteger = 0x8D9C, kLuminanceAlphaInteger = 0x8D9D;
constexpr GLenum kHalfFloatOes = 0x8D61;

// Components a pixel of `format` has in memory (table 8.3); 0 if unknown.
size_t components(GLenum format) {
  switch (format) {
    case GL_RED: case GL_GREEN: case GL_BLUE: case GL_ALPHA: case kLuminance: case kColorIndex:
    case GL_RED_INTEGER: case GL_GREEN_INTEGER: case GL_BLUE_INTEGER: case kAlphaInteger: case kLuminanceInteger:
    case GL_DEPTH_COMPONENT: case GL_STENCIL_INDEX:
      return 1;
    case GL_RG: case GL_RG_INTEGER: case kLuminanceAlpha: case kLuminanceAlphaInteger: case GL_DEPTH_STENCIL:
      return 2;
    case GL_RGB: case GL_BGR: case GL_RGB_INTEGER: case GL_BGR_INTEGER:
      return 3;
    case GL_RGBA: case GL_BGRA: case GL_RGBA_INTEGER: case GL_BGRA_INTEGER: case kAbgrExt:
      return 4;
    default:
      return 0;
  }
}

// Bytes of one component of an unpacked type (table 8.2); 0 if `type` is packed or unknown.
size_t componentBytes(GLenum type) {
  switch (type) {
    case GL_UNSIGNED_BYTE: case GL_BYTE: return 1;
    case GL_UNSIGNED_SHORT: case GL_SHORT: case GL_HALF_FLOAT: case kHalfFloatOes: return 2;
    case GL_UNSIGNED_INT: case GL_INT: case GL_FLOAT: return 4;
    default: return 0;
  }
}

// A packed type (tables 8.5-8.8): its bytes a pixel and the components of the formats it packs
// (0 if `type` is not packed).
struct Packed {
  size_t bytes = 0;
  size_t components = 0;
};
Packed packed(GLenum type) {
  switch (type) {
    case GL_UNSIGNED_BYTE_3_3_2: case GL_UNSIGNED_BYTE_2_3_3_REV: return {1, 3};
    case GL_UNSIGNED_SHORT_5_6_5: case GL_UNSIGNED_SHORT_5_6_5_REV: return {2, 3};
    case GL_UNSIGNED_SHORT_4_4_4_4: case GL_UNSIGNED_SHORT_4_4_4_4_REV: case GL_UNSIGNED_SHORT_5_5_5_1:
    case GL_UNSIGNED_SHORT_1_5_5_5_REV:
      return {2, 4};
    case GL_UNSIGNED_INT_8_8_8_8: case GL_UNSIGNED_INT_8_8_8_8_REV: case GL_UNSIGNED_INT_10_10_10_2:
    case GL_UNSIGNED_INT_2_10_10_10_REV:
      return {4, 4};
    case GL_UNSIGNED_INT_10F_11F_11F_REV: case GL_UNSIGNED_INT_5_9_9_9_REV: return {4, 3};
    case GL_UNSIGNED_INT_24_8: return {4, 2};
    case GL_FLOAT_32_UNSIGNED_INT_24_8_REV: return {8, 2};
    default: return {};
  }
}

}  // namespace

size_t pixelBytes(GLenum format, GLenum type) {
  if (type == kBitmap) return 0;
  const size_t n = components(format);
  if (n == 0) return 0;
  const Packed p = packed(type);
  if (p.bytes) return n == p.components ? p.bytes : 0;  // a packed type fills exactly its formats
  if (format == GL_DEPTH_STENCIL) return 0;               // only packed (24_8, 32F_24_8_REV)
  return n * componentBytes(type);
}

bool unpackedSpan(GLenum format, GLenum type, GLsizei width, GLsizei height, const UnpackState& unpack,
                  UnpackedSpan& out) {
  const size_t pixel = pixelBytes(format, type);
  if (pixel == 0 || width <= 0 || height <= 0) return false;
  if (unpack.row_length < 0 || unpack.skip_pixels < 0 || unpack.skip_rows < 0) return false;
  const size_t a = unpack.alignment == 1 || unpack.alignment == 2 || unpack.alignment == 4 || unpack.alignment == 8
                       ? static_cast<size_t>(unpack.alignment) : 4;
  // One element: a component, or the whole pixel of a packed type.
  const size_t element = packed(type).bytes ? pixel : componentBytes(type);
  const size_t row_pixels = static_cast<size_t>(unpack.row_length > 0 ? unpack.row_length : width);
  const size_t row = row_pixels * pixel;
  out.stride = element >= a ? row : (row + a - 1) / a * a;
  out.offset = static_cast<size_t>(unpack.skip_pixels) * pixel + static_cast<size_t>(unpack.skip_rows) * out.stride;
  out.bytes = out.stride * static_cast<size_t>(height - 1) + static_cast<size_t>(width) * pixel;
  return true;
}

}  // namespace capture
}  // namespace viper
