#include "frame_target.h"

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <thread>
#include <type_traits>

namespace viper {
namespace capture {

void FrameTarget::queryDefaultFormats() {
  const RealGl& g = gl();
  dsa_ = glVersionAtLeast(4, 5);
  const GLint prev_draw = glInt(GL_DRAW_FRAMEBUFFER_BINDING);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  const GLenum color_att = glInt(GL_DOUBLEBUFFER) ? GL_BACK_LEFT : GL_FRONT_LEFT;
  // The window's own draw and read buffers, as the program will ask for them.
  window_draw_buffer_ = static_cast<GLenum>(glInt(GL_DRAW_BUFFER));
  program_draw_buffers.assign(1, window_draw_buffer_);
  const GLint prev_read = glInt(GL_READ_FRAMEBUFFER_BINDING);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  program_read_buffer = static_cast<GLenum>(glInt(GL_READ_BUFFER));
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, prev_read);
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
  // Pixel-pack buffers: unmapped only once no writer thread reads them (the interceptor has
  // handed every pending frame over by now, so they are all on their way out).
  for (PackBuffer& b : pack_buffers_) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (b.in_use->load() && std::chrono::steady_clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (b.in_use->load()) {
      std::fprintf(stderr, "[viper capture] a read-back buffer is still in use after 10 s: left mapped\n");
      continue;
    }
    const GLint prev = glInt(GL_PIXEL_PACK_BUFFER_BINDING);
    g.BindBuffer(GL_PIXEL_PACK_BUFFER, b.name);
    g.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
    g.BindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(prev));
    g.DeleteBuffers(1, &b.name);
  }
  pack_buffers_.clear();
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

void FrameTarget::giveUp() {
  given_up_ = true;
  if (!fbo_) return;
  const RealGl& g = gl();
  const GLboolean scissor = g.IsEnabled(GL_SCISSOR_TEST);
  if (scissor) g.Disable(GL_SCISSOR_TEST);
  // The program's framebuffer objects lose our id attachment and get their own draw buffers back.
  for (auto& [name, f] : program_fbos_) {
    if (!f.ids) continue;
    g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, name);
    g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, kIdAttachment, GL_TEXTURE_2D, 0, 0);
    g.DrawBuffers(static_cast<GLsizei>(f.program_draw_buffers.size()), f.program_draw_buffers.data());
  }
  // What the program drew so far, into the window's buffer it was drawing for.
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  g.ReadBuffer(GL_COLOR_ATTACHMENT0);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  g.DrawBuffer(window_draw_buffer_);
  GLbitfield mask = GL_COLOR_BUFFER_BIT;
  if (depth_) mask |= GL_DEPTH_BUFFER_BIT | (depth_attachment_ == GL_DEPTH_STENCIL_ATTACHMENT ? GL_STENCIL_BUFFER_BIT : 0);
  g.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, mask, GL_NEAREST);
  if (scissor) g.Enable(GL_SCISSOR_TEST);
  // The window's framebuffer as the program set it up.
  g.DrawBuffers(static_cast<GLsizei>(program_draw_buffers.size()), program_draw_buffers.data());
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  g.ReadBuffer(program_read_buffer);
  g.BindFramebuffer(GL_DRAW_FRAMEBUFFER, program_draw_fb);
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, program_read_fb);
  destroy();
}

void FrameTarget::ensureSize(int width, int height) {
  if (given_up_) return;
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
  const GLenum none_or_color = programDrawBuffer() == GL_NONE ? GL_NONE : GL_COLOR_ATTACHMENT0;
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

bool FrameTarget::packBuffersInUse() const {
  for (const PackBuffer& b : pack_buffers_)
    if (b.in_use->load()) return true;
  return false;
}

bool FrameTarget::presentAsync(RawImages& out, bool to_surface, GLsync& fence) {
  const RealGl& g = gl();
  if (!fbo_) return false;
  if (async_supported_ < 0) {
    bool storage = glVersionAtLeast(4, 4);
    const GLint extensions = glInt(GL_NUM_EXTENSIONS);
    for (GLint i = 0; !storage && g.GetStringi && i < extensions; ++i) {
      const GLubyte* name = g.GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
      storage = name && std::strcmp(reinterpret_cast<const char*>(name), "GL_ARB_buffer_storage") == 0;
    }
    async_supported_ = storage && g.BufferStorage && g.FenceSync && g.ClientWaitSync && g.MapBufferRange;
    if (!async_supported_)
      std::fprintf(stderr, "[viper capture] no glBufferStorage in this context: frames are read back synchronously\n");
  }
  if (!async_supported_) return false;
  // 16 bytes a pixel hold every image present() reads: color 4, depth 4, ids 8.
  const size_t bytes = static_cast<size_t>(width_) * height_ * 16;
  if (pack_buffers_.empty()) {
    const GLint prev = glInt(GL_PIXEL_PACK_BUFFER_BINDING);
    for (size_t i = 0; i < pack_buffer_count; ++i) {
      PackBuffer b;
      g.GenBuffers(1, &b.name);
      g.BindBuffer(GL_PIXEL_PACK_BUFFER, b.name);
      const GLbitfield flags = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
      g.BufferStorage(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr, flags | GL_CLIENT_STORAGE_BIT);
      b.mapped = static_cast<const uint8_t*>(g.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(bytes), flags));
      if (!b.mapped) {
        g.DeleteBuffers(1, &b.name);
        break;
      }
      pack_buffers_.push_back(std::move(b));
    }
    g.BindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(prev));
    if (pack_buffers_.empty()) {
      std::fprintf(stderr, "[viper capture] read-back buffers could not be mapped: frames are read back synchronously\n");
      async_supported_ = 0;
      return false;
    }
  }
  PackBuffer* free_buffer = nullptr;
  for (PackBuffer& b : pack_buffers_)
    if (!b.in_use->load()) free_buffer = &b;
  if (!free_buffer) return false;
  free_buffer->in_use->store(true);
  presentInto(out, to_surface, true, free_buffer);
  out.view_owner = free_buffer->in_use;
  fence = g.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  return true;
}

void FrameTarget::present(RawImages& out, bool to_surface, bool read_back) {
  presentInto(out, to_surface, read_back, nullptr);
}

void FrameTarget::presentInto(RawImages& out, bool to_surface, bool read_back, PackBuffer* into) {
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

  g.BindBuffer(GL_PIXEL_PACK_BUFFER, into ? into->name : 0);
  g.PixelStorei(GL_PACK_ALIGNMENT, 1);
  g.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  g.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  g.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  const size_t n = static_cast<size_t>(width_) * height_;
  out.releaseViews();
  // Where each image goes: its vector, or the next piece of the pixel-pack buffer (and its view).
  size_t offset = 0;
  auto place = [&](auto& vector, size_t count, auto& view) -> void* {
    using T = typename std::decay_t<decltype(vector)>::value_type;
    if (!into) {
      vector.resize(count);
      return vector.data();
    }
    vector.clear();
    view = reinterpret_cast<const T*>(into->mapped + offset);
    void* at = reinterpret_cast<void*>(offset);
    offset += count * sizeof(T);
    return at;
  };
  const auto reads_start = std::chrono::steady_clock::now();
  if (scene_color_taken_) g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene_color_fbo_);  // the scene without its overlay
  g.ReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, place(out.rgba, n * 4, out.rgba_view));
  g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  out.depth.clear();
  out.depth_24_8.clear();
  const GLuint scene = sceneSource();
  out.depth_ids_top_first = false;
  if (scene) {
    // Shown in the window upside down (its color image blitted there flipped): its rows, read
    // bottom first, are the window's top first.
    const ProgramFbo& f = program_fbos_.at(scene);
    out.depth_ids_top_first =
        window_blit_flipped_ && window_blit_source_.type != GL_NONE && window_blit_source_ == f.color;
    // The scene was drawn into a framebuffer object of the program's and composited: its depth and
    // our ids there, read without changing the read buffer the program set on it.
    g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene);
    const GLint program_read_buffer = glInt(GL_READ_BUFFER);
    g.ReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, place(out.depth, n, out.depth_view));
    g.ReadBuffer(kIdAttachment);
    g.ReadPixels(0, 0, width_, height_, GL_RG, GL_FLOAT, place(out.ids, n * 2, out.ids_view));
    g.ReadBuffer(static_cast<GLenum>(program_read_buffer));
  } else {
    // The scene's depth as it was when the scene ended (endScene), or as it is now.
    if (scene_depth_taken_) g.BindFramebuffer(GL_READ_FRAMEBUFFER, scene_color_fbo_);
    if (depth_format_ == GL_DEPTH24_STENCIL8) {
      // Packed read-back is a plain copy; the conversion to float happens on the writer thread.
      g.ReadPixels(0, 0, width_, height_, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8,
                   place(out.depth_24_8, n, out.depth_24_8_view));
    } else if (depth_) {
      g.ReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, place(out.depth, n, out.depth_view));
    }
    g.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  }
  if (!scene) {
    g.ReadBuffer(GL_COLOR_ATTACHMENT1);
    g.ReadPixels(0, 0, width_, height_, GL_RG, GL_FLOAT, place(out.ids, n * 2, out.ids_view));
  }
  read_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - reads_start).count();
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
