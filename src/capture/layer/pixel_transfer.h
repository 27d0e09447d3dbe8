// How many bytes of the program's memory a pixel upload reads: one table of the pixel formats and
// types of the GL specification, and its unpacking rule. The layer hashes exactly those bytes (a
// texture's content key), never more.
#pragma once

#include <GL/glcorearb.h>

#include <cstddef>

namespace viper {
namespace capture {

/// Bytes of one pixel in client memory for a pixel transfer of `format` and `type`: the GL 4.6
/// compatibility profile's table 8.2 (types), 8.3 (formats, legacy ones included: GL_ALPHA,
/// GL_LUMINANCE, GL_LUMINANCE_ALPHA, GL_COLOR_INDEX...) and 8.5-8.8 (packed types, one element a
/// pixel whatever the format). 0 for a combination the GL rejects, for GL_BITMAP (bits, not bytes)
/// and for anything unknown: the caller then reads nothing.
size_t pixelBytes(GLenum format, GLenum type);

/// The unpack state of the context (GL_UNPACK_ROW_LENGTH, _SKIP_PIXELS, _SKIP_ROWS, _ALIGNMENT).
struct UnpackState {
  GLint row_length = 0;
  GLint skip_pixels = 0;
  GLint skip_rows = 0;
  GLint alignment = 4;
};

/// Where an upload of `width` x `height` pixels starts past the pointer it is given, and how many
/// bytes it reads from there (section 8.4.4.1, "Unpacking"): rows `stride` bytes apart, each
/// padded to the alignment unless one element is at least that large. False (nothing to read) for
/// an empty image, a format the table does not know, or a negative unpack state.
struct UnpackedSpan {
  size_t offset = 0;  ///< bytes from the pointer to the first pixel read
  size_t bytes = 0;   ///< bytes read from there
  size_t stride = 0;  ///< bytes from one row to the next
};
bool unpackedSpan(GLenum format, GLenum type, GLsizei width, GLsizei height, const UnpackState& unpack,
                  UnpackedSpan& out);

}  // namespace capture
}  // namespace viper
