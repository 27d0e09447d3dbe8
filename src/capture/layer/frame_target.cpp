#include "frame_target.h"

#include <cstddef>

namespace viper {
namespace capture {

void FrameTarget::queryDefaultFormats() {
  const RealGl& g = gl();
  const GLint prev_draw = glInt(GL_DRAW_FRAMEBUFFER_BINDING);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  const GLenum color_att = glInt(GL_DOUBLEBUFFER) ? GL_BACK_LEFT : GL_FRONT_LEFT;
  const bool srgb = drawAttachmentParam(color_att, GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING) == GL_SRGB;
  const bool alpha = drawAttachmentParam(color_att, GL_FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE) > 0;
  color_format_ = alpha ? (srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8) : (srgb ? GL_SRGB8 : GL_RGB8);

  GLint depth_bits = 0, stencil_bits = 0;
  if (drawAttachmentParam(GL_DEPTH, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) != GL_NONE)
    depth_bits = drawAttachmentParam(GL_DEPTH, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE);
  if (drawAttachmentParam(GL_STENCIL, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) != GL_NONE)
    stencil_bits = drawAttachmentParam(GL_STENCIL, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE);
  // Same depth precision as the real framebuffer, so depth tests (and pixels) come out identical.
  depth_attachment_ = stencil_bits > 0 ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT;
  if (depth_bits == 0) depth_format_ = 0;
  else if (depth_bits <= 16 && stencil_bits == 0) depth_format_ = GL_DEPTH_COMPONENT16;
  else if (depth_bits <= 24) depth_format_ = stencil_bits > 0 ? GL_DEPTH24_STENCIL8 : GL_DEPTH_COMPONENT24;
  else depth_format_ = stencil_bits > 0 ? GL_DEPTH32F_STENCIL8 : GL_DEPTH_COMPONENT32F;
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, prev_draw);
  formats_known_ = true;
}

void FrameTarget::destroy() {
  const RealGl& g = gl();
  if (fbo_) g.DeleteFramebuffers(1, &fbo_);
  GLuint tex[3] = {color_, ids_, depth_};
  g.DeleteTextures(3, tex);
  fbo_ = color_ = ids_ = depth_ = 0;
  if (scene_color_fbo_) g.DeleteFramebuffers(1, &scene_color_fbo_);
  if (scene_color_) g.DeleteTextures(1, &scene_color_);
  if (scene_depth_) g.DeleteTextures(1, &scene_depth_);
  scene_color_fbo_ = scene_color_ = scene_depth_ = 0;
  scene_color_taken_ = scene_depth_taken_ = scene_ended_ = false;
  // Id textures of the program's framebuffer objects: made again at the new size when next drawn.
  for (auto& [name, f] : program_fbos_) g.DeleteTextures(1, &f.ids);
  program_fbos_.clear();
}

void FrameTarget::ensureSize(int width, int height) {
  if (width <= 0 || height <= 0 || (fbo_ && width == width_ && height == height_)) return;
  const RealGl& g = gl();
  if (!formats_known_) queryDefaultFormats();
  destroy();
  width_ = width;
  height_ = height;

  const GLint prev_tex = glInt(GL_TEXTURE_BINDING_2D);
  const GLint prev_unpack = glInt(GL_PIXEL_UNPACK_BUFFER_BINDING);
  g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  auto make = [&](GLenum internal, GLenum format, GLenum type) {
    GLuint t = 0;
    g.GenTextures(1, &t);
    g.BindTexture(GL_TEXTURE_2D, t);
    g.TexImage2D(GL_TEXTURE_2D, 0, internal, width, height, 0, format, type, nullptr);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    return t;
  };
  color_ = make(color_format_, GL_RGBA, GL_UNSIGNED_BYTE);
  ids_ = make(GL_RG32F, GL_RG, GL_FLOAT);
  if (depth_format_ != 0) {
    const bool stencil = depth_attachment_ == GL_DEPTH_STENCIL_ATTACHMENT;
    depth_ = make(depth_format_, stencil ? GL_DEPTH_STENCIL : GL_DEPTH_COMPONENT,
                  stencil ? (depth_format_ == GL_DEPTH24_STENCIL8 ? GL_UNSIGNED_INT_24_8
                                                                 : GL_FLOAT_32_UNSIGNED_INT_24_8_REV)
                          : GL_FLOAT);
  }
  g.BindTexture(GL_TEXTURE_2D, prev_tex);
  g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, prev_unpack);

  g.GenFramebuffers(1, &fbo_);
  g.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_, 0);
  g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, ids_, 0);
  if (depth_) g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, depth_attachment_, GL_TEXTURE_2D, depth_, 0);
  ids_enabled = true;
  applyDrawBuffers(true);
  applyReadBuffer();
  // The new attachments start as a cleared default framebuffer would: zero color, far depth.
  const GLfloat zero[4] = {0, 0, 0, 0};
  const GLint prev_scissor = g.IsEnabled(GL_SCISSOR_TEST);
  g.Disable(GL_SCISSOR_TEST);
  g.ClearBufferfv(GL_COLOR, 0, zero);
  g.ClearBufferfv(GL_COLOR, kIdDrawBuffer, zero);
  if (prev_scissor) g.Enable(GL_SCISSOR_TEST);
  // Where the program thinks the default framebuffer is bound, ours is.
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, program_draw_fb ? program_draw_fb : fbo_);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, program_read_fb ? program_read_fb : fbo_);
}

void FrameTarget::applyDrawBuffers(bool ids) {
  const GLenum none_or_color = program_draw_buffer == GL_NONE ? GL_NONE : GL_COLOR_ATTACHMENT0;
  const GLenum ids_buffer = ids && none_or_color != GL_NONE ? GLenum(GL_COLOR_ATTACHMENT1) : GLenum(GL_NONE);
  GLenum bufs[kIdDrawBuffer + 1];
  bufs[0] = none_or_color;
  for (GLuint i = 1; i < kIdDrawBuffer; ++i) bufs[i] = GL_NONE;
  bufs[kIdDrawBuffer] = ids_buffer;
  gl().DrawBuffers(kIdDrawBuffer + 1, bufs);
  ids_enabled = ids;
}

void FrameTarget::applyReadBuffer() {
  gl().ReadBuffer(program_read_buffer == GL_NONE ? GL_NONE : GL_COLOR_ATTACHMENT0);
}

void FrameTarget::snapshotScene(bool with_depth) {
  if (!fbo_ || (scene_color_taken_ && (!with_depth || scene_depth_taken_))) return;
  const RealGl& g = gl();
  if (!scene_color_fbo_) {
    const GLint prev_tex = glInt(GL_TEXTURE_BINDING_2D);
    const GLint prev_unpack = glInt(GL_PIXEL_UNPACK_BUFFER_BINDING);
    g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    g.GenTextures(1, &scene_color_);
    g.BindTexture(GL_TEXTURE_2D, scene_color_);
    g.TexImage2D(GL_TEXTURE_2D, 0, color_format_, width_, height_, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    if (depth_format_) {  // same format as ours, so that a blit copies it
      g.GenTextures(1, &scene_depth_);
      g.BindTexture(GL_TEXTURE_2D, scene_depth_);
      g.TexStorage2D(GL_TEXTURE_2D, 1, depth_format_, width_, height_);
    }
    g.BindTexture(GL_TEXTURE_2D, static_cast<GLuint>(prev_tex));
    g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, static_cast<GLuint>(prev_unpack));
    const GLint prev_draw = glInt(GL_DRAW_FRAMEBUFFER_BINDING);
    g.GenFramebuffers(1, &scene_color_fbo_);
    g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, scene_color_fbo_);
    g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, scene_color_, 0);
    if (scene_depth_) g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, depth_attachment_, GL_TEXTURE_2D, scene_depth_, 0);
    g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(prev_draw));
  }
  const GLint prev_draw = glInt(GL_DRAW_FRAMEBUFFER_BINDING), prev_read = glInt(GL_READ_FRAMEBUFFER_BINDING);
  const GLint prev_read_buffer = glInt(GL_READ_BUFFER);
  const GLboolean scissor = g.IsEnabled(GL_SCISSOR_TEST);
  const GLboolean srgb = g.IsEnabled(GL_FRAMEBUFFER_SRGB);
  if (scissor) g.Disable(GL_SCISSOR_TEST);
  if (srgb) g.Disable(GL_FRAMEBUFFER_SRGB);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  g.ReadBuffer(GL_COLOR_ATTACHMENT0);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, scene_color_fbo_);
  GLbitfield mask = scene_color_taken_ ? 0 : GL_COLOR_BUFFER_BIT;
  if (with_depth && scene_depth_) mask |= GL_DEPTH_BUFFER_BIT;
  if (mask) g.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, mask, GL_NEAREST);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  g.ReadBuffer(static_cast<GLenum>(prev_read_buffer));
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(prev_draw));
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(prev_read));
  if (scissor) g.Enable(GL_SCISSOR_TEST);
  if (srgb) g.Enable(GL_FRAMEBUFFER_SRGB);
  scene_color_taken_ = true;
  if (with_depth && scene_depth_) scene_depth_taken_ = true;
}

void FrameTarget::present(RawImages& out, bool to_surface, bool read_back) {
  const RealGl& g = gl();
  out.width = width_;
  out.height = height_;
  if (!fbo_) return;
  const GLint pack_buffer = glInt(GL_PIXEL_PACK_BUFFER_BINDING);
  const GLint pack_alignment = glInt(GL_PACK_ALIGNMENT);
  const GLint pack_row_length = glInt(GL_PACK_ROW_LENGTH);
  const GLint pack_skip_rows = glInt(GL_PACK_SKIP_ROWS);
  const GLint pack_skip_pixels = glInt(GL_PACK_SKIP_PIXELS);
  const GLboolean scissor = g.IsEnabled(GL_SCISSOR_TEST);
  const GLboolean srgb = g.IsEnabled(GL_FRAMEBUFFER_SRGB);
  const GLboolean discard = g.IsEnabled(GL_RASTERIZER_DISCARD);
  if (scissor) g.Disable(GL_SCISSOR_TEST);
  if (srgb) g.Disable(GL_FRAMEBUFFER_SRGB);
  if (discard) g.Disable(GL_RASTERIZER_DISCARD);

  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  g.ReadBuffer(GL_COLOR_ATTACHMENT0);
  if (to_surface) {
    g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    g.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  if (!read_back) {
    out.rgba.clear(), out.depth.clear(), out.depth_24_8.clear(), out.ids.clear();
    endFrame();
    if (scissor) g.Enable(GL_SCISSOR_TEST);
    if (srgb) g.Enable(GL_FRAMEBUFFER_SRGB);
    if (discard) g.Enable(GL_RASTERIZER_DISCARD);
    g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, program_draw_fb ? program_draw_fb : fbo_);
    g.BindFramebuffer(GL_READ_FRAMEBUFFER, program_read_fb ? program_read_fb : fbo_);
    applyReadBuffer();
    return;
  }

  g.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  g.PixelStorei(GL_PACK_ALIGNMENT, 1);
  g.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  g.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  g.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  const size_t n = static_cast<size_t>(width_) * height_;
  out.rgba.resize(n * 4);
  if (scene_color_taken_) g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene_color_fbo_);  // the scene without its overlay
  g.ReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.rgba.data());
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  out.depth.clear();
  out.depth_24_8.clear();
  const GLuint scene = sceneSource();
  if (scene) {
    // The scene was drawn into a framebuffer object of the program's and composited: its depth and
    // our ids there, read without changing the read buffer the program set on it.
    g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene);
    const GLint program_read_buffer = glInt(GL_READ_BUFFER);
    out.depth.resize(n);
    g.ReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth.data());
    g.ReadBuffer(kIdAttachment);
    out.ids.resize(n * 2);
    g.ReadPixels(0, 0, width_, height_, GL_RG, GL_FLOAT, out.ids.data());
    g.ReadBuffer(static_cast<GLenum>(program_read_buffer));
  } else {
    // The scene's depth as it was when the scene ended (endScene), or as it is now.
    if (scene_depth_taken_) g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene_color_fbo_);
    if (depth_format_ == GL_DEPTH24_STENCIL8) {
      // Packed read-back is a plain copy; the conversion to float happens on the writer thread.
      out.depth_24_8.resize(n);
      g.ReadPixels(0, 0, width_, height_, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, out.depth_24_8.data());
    } else if (depth_) {
      out.depth.resize(n);
      g.ReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth.data());
    }
    g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  }
  if (!scene) {
    g.ReadBuffer(GL_COLOR_ATTACHMENT1);
    out.ids.resize(n * 2);
    g.ReadPixels(0, 0, width_, height_, GL_RG, GL_FLOAT, out.ids.data());
  }
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  applyReadBuffer();
  endFrame();

  g.BindBuffer(GL_PIXEL_PACK_BUFFER, pack_buffer);
  g.PixelStorei(GL_PACK_ALIGNMENT, pack_alignment);
  g.PixelStorei(GL_PACK_ROW_LENGTH, pack_row_length);
  g.PixelStorei(GL_PACK_SKIP_ROWS, pack_skip_rows);
  g.PixelStorei(GL_PACK_SKIP_PIXELS, pack_skip_pixels);
  if (scissor) g.Enable(GL_SCISSOR_TEST);
  if (srgb) g.Enable(GL_FRAMEBUFFER_SRGB);
  if (discard) g.Enable(GL_RASTERIZER_DISCARD);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, program_draw_fb ? program_draw_fb : fbo_);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, program_read_fb ? program_read_fb : fbo_);
}

}  // namespace capture
}  // namespace viper
