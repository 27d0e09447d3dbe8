// The layer's table of pixel formats and types (src/capture/layer/pixel_transfer.h) against the
// GL itself: for every format and type, the driver uploads a texture from a pixel-unpack buffer of
// exactly the size the table says and refuses one a byte shorter (the GL checks that an upload
// stays inside its buffer), under alignments, row lengths and skips; and every combination the
// driver takes, the table knows. The layer hashes exactly these bytes of a program's memory, so a
// size too large reads past the program's buffer (GL_ALPHA as 4 bytes a pixel crashed a game), one
// too small keys textures wrongly.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include "egl_pbuffer.h"
#include "pixel_transfer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

using viper::capture::pixelBytes;
using viper::capture::UnpackedSpan;
using viper::capture::unpackedSpan;
using viper::capture::UnpackState;

// Every format and type of the GL 4.6 compatibility profile's tables 8.2-8.8, the legacy and
// extension ones included, and some that are not pixel formats or types at all.
const GLenum kFormats[] = {
    GL_RED, GL_GREEN, GL_BLUE, GL_ALPHA, 0x1909 /*LUMINANCE*/, 0x190A /*LUMINANCE_ALPHA*/, 0x1900 /*COLOR_INDEX*/,
    GL_RG, GL_RGB, GL_BGR, GL_RGBA, GL_BGRA, 0x8000 /*ABGR_EXT*/, GL_RED_INTEGER, GL_GREEN_INTEGER, GL_BLUE_INTEGER,
    0x8D97 /*ALPHA_INTEGER*/, 0x8D9C /*LUMINANCE_INTEGER_EXT*/, 0x8D9D /*LUMINANCE_ALPHA_INTEGER_EXT*/,
    GL_RG_INTEGER, GL_RGB_INTEGER, GL_BGR_INTEGER, GL_RGBA_INTEGER, GL_BGRA_INTEGER, GL_DEPTH_COMPONENT,
    GL_STENCIL_INDEX, GL_DEPTH_STENCIL, 0x8049 /*INTENSITY: an internal format only*/, GL_RGBA8 /*not a format*/};
const GLenum kTypes[] = {
    GL_UNSIGNED_BYTE, GL_BYTE, GL_UNSIGNED_SHORT, GL_SHORT, GL_UNSIGNED_INT, GL_INT, GL_HALF_FLOAT, GL_FLOAT,
    GL_UNSIGNED_BYTE_3_3_2, GL_UNSIGNED_BYTE_2_3_3_REV, GL_UNSIGNED_SHORT_5_6_5, GL_UNSIGNED_SHORT_5_6_5_REV,
    GL_UNSIGNED_SHORT_4_4_4_4, GL_UNSIGNED_SHORT_4_4_4_4_REV, GL_UNSIGNED_SHORT_5_5_5_1,
    GL_UNSIGNED_SHORT_1_5_5_5_REV, GL_UNSIGNED_INT_8_8_8_8, GL_UNSIGNED_INT_8_8_8_8_REV, GL_UNSIGNED_INT_10_10_10_2,
    GL_UNSIGNED_INT_2_10_10_10_REV, GL_UNSIGNED_INT_10F_11F_11F_REV, GL_UNSIGNED_INT_5_9_9_9_REV,
    GL_UNSIGNED_INT_24_8, GL_FLOAT_32_UNSIGNED_INT_24_8_REV, 0x1A00 /*BITMAP*/, GL_DOUBLE /*not a pixel type*/};

bool isInteger(GLenum format) {
  switch (format) {
    case GL_RED_INTEGER: case GL_GREEN_INTEGER: case GL_BLUE_INTEGER: case 0x8D97: case 0x8D9C: case 0x8D9D:
    case GL_RG_INTEGER: case GL_RGB_INTEGER: case GL_BGR_INTEGER: case GL_RGBA_INTEGER: case GL_BGRA_INTEGER:
      return true;
    default:
      return false;
  }
}

// A texture internal format that the GL pairs with `format` and `type`.
GLenum internalFormatFor(GLenum format, GLenum type) {
  if (isInteger(format)) return GL_RGBA32UI;
  if (format == GL_DEPTH_COMPONENT) return GL_DEPTH_COMPONENT32F;
  if (format == GL_STENCIL_INDEX) return GL_STENCIL_INDEX8;
  if (format == GL_DEPTH_STENCIL)
    return type == GL_FLOAT_32_UNSIGNED_INT_24_8_REV ? GL_DEPTH32F_STENCIL8 : GL_DEPTH24_STENCIL8;
  return GL_RGBA8;
}

std::string name(GLenum e) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%04x", static_cast<unsigned>(e));
  return text;
}

class PixelTransfer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const EGLint compat[] = {EGL_NONE};  // the compatibility profile, for the legacy formats
    viper::test_program::makeCurrentPbuffer("test_pixel_transfer", 16, 16, compat, "OpenGL context");
  }
  void SetUp() override {
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glGenBuffers(1, &buffer_);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer_);
    while (glGetError() != GL_NO_ERROR) {
    }
  }
  void TearDown() override {
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glDeleteBuffers(1, &buffer_);
    glDeleteTextures(1, &texture_);
  }
  // The GL's error for an upload of w x h from the start of an unpack buffer of `size` bytes.
  GLenum upload(GLenum format, GLenum type, GLsizei w, GLsizei h, size_t size) {
    glBufferData(GL_PIXEL_UNPACK_BUFFER, static_cast<GLsizeiptr>(size), nullptr, GL_STREAM_DRAW);
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internalFormatFor(format, type)), w, h, 0, format, type,
                 nullptr);
    GLenum error = glGetError();
    while (glGetError() != GL_NO_ERROR) {
    }
    return error;
  }
  static void setUnpack(const UnpackState& u) {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, u.row_length);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, u.skip_pixels);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, u.skip_rows);
    glPixelStorei(GL_UNPACK_ALIGNMENT, u.alignment);
  }
  GLuint texture_ = 0, buffer_ = 0;
};

TEST_F(PixelTransfer, EveryCombinationTheGlTakesIsSizedExactly) {
  int accepted = 0, checked_states = 0;
  for (GLenum format : kFormats) {
    for (GLenum type : kTypes) {
      // (Mesa takes stencil indices of any type into a GL_STENCIL_INDEX8 texture, then cannot
      // store them and prints so for every row: only bytes are tried.)
      if (format == GL_STENCIL_INDEX && type != GL_UNSIGNED_BYTE) continue;
      setUnpack(UnpackState{});
      const bool taken = upload(format, type, 3, 2, 1 << 16) == GL_NO_ERROR;
      const size_t pixel = pixelBytes(format, type);
      SCOPED_TRACE("format " + name(format) + ", type " + name(type));
      if (!taken) continue;
      if (type == 0x1A00 /*BITMAP*/) {
        // Bits, not bytes (colour-index and stencil bitmaps): the table sizes none, and the layer
        // reads none of such an upload (its texture is keyed by its size).
        EXPECT_EQ(pixel, 0u);
        continue;
      }
      ++accepted;
      ASSERT_GT(pixel, 0u) << "the GL takes this combination; the table does not know it";
      for (GLint alignment : {1, 2, 4, 8})
        for (GLint row_length : {0, 9})
          for (GLint skip_pixels : {0, 2})
            for (GLint skip_rows : {0, 1})
              for (GLsizei w : {1, 5, 7})
                for (GLsizei h : {1, 3}) {
                  const UnpackState u{row_length, skip_pixels, skip_rows, alignment};
                  UnpackedSpan span;
                  ASSERT_TRUE(unpackedSpan(format, type, w, h, u, span));
                  setUnpack(u);
                  const size_t end = span.offset + span.bytes;
                  SCOPED_TRACE("alignment " + std::to_string(alignment) + ", row length " +
                               std::to_string(row_length) + ", skip " + std::to_string(skip_pixels) + "," +
                               std::to_string(skip_rows) + ", " + std::to_string(w) + "x" + std::to_string(h));
                  EXPECT_EQ(upload(format, type, w, h, end), GLenum(GL_NO_ERROR)) << "table too large";
                  EXPECT_EQ(upload(format, type, w, h, end - 1), GLenum(GL_INVALID_OPERATION)) << "table too small";
                  ++checked_states;
                }
    }
  }
  setUnpack(UnpackState{});
  // The driver's compatibility profile takes the legacy formats the layer met in games (GL_ALPHA,
  // GL_LUMINANCE, GL_LUMINANCE_ALPHA) and the core ones: far more than a handful.
  EXPECT_GT(accepted, 100) << "the GL took only " << accepted << " combinations: no compatibility context?";
  std::printf("%d format/type combinations the GL takes, each sized exactly in %d unpack states\n", accepted,
              checked_states / (accepted > 0 ? accepted : 1));
}

TEST_F(PixelTransfer, TheLegacyFormatsOfGamesAreOneAndTwoBytesAPixel) {
  EXPECT_EQ(pixelBytes(GL_ALPHA, GL_UNSIGNED_BYTE), 1u);
  EXPECT_EQ(pixelBytes(0x1909 /*LUMINANCE*/, GL_UNSIGNED_BYTE), 1u);
  EXPECT_EQ(pixelBytes(0x190A /*LUMINANCE_ALPHA*/, GL_UNSIGNED_BYTE), 2u);
  EXPECT_EQ(pixelBytes(0x8049 /*INTENSITY*/, GL_UNSIGNED_BYTE), 0u);  // not a format: nothing is read
  // The 1024x1024 GL_ALPHA upload that crashed a game under the layer: 1 MB, not 4.
  UnpackedSpan span;
  ASSERT_TRUE(unpackedSpan(GL_ALPHA, GL_UNSIGNED_BYTE, 1024, 1024, UnpackState{}, span));
  EXPECT_EQ(span.offset + span.bytes, 1024u * 1024u);
}

TEST_F(PixelTransfer, NothingIsReadForWhatTheTableDoesNotKnow) {
  UnpackedSpan span;
  EXPECT_FALSE(unpackedSpan(0x1900 /*COLOR_INDEX*/, 0x1A00 /*BITMAP*/, 8, 8, UnpackState{}, span));
  EXPECT_FALSE(unpackedSpan(GL_RGBA, GL_DOUBLE, 8, 8, UnpackState{}, span));
  EXPECT_FALSE(unpackedSpan(GL_RGB, GL_UNSIGNED_SHORT_4_4_4_4, 8, 8, UnpackState{}, span));  // packs 4, not 3
  EXPECT_FALSE(unpackedSpan(GL_RGBA, GL_UNSIGNED_BYTE, 0, 8, UnpackState{}, span));
  UnpackState negative;
  negative.skip_rows = -1;
  EXPECT_FALSE(unpackedSpan(GL_RGBA, GL_UNSIGNED_BYTE, 8, 8, negative, span));
}

}  // namespace
