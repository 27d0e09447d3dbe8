// The program's own framebuffer objects that may hold its scene (FrameTarget::ProgramFbo): which
// qualify, our id attachment on them, their draw buffers and clears.
#include "frame_target.h"

#include <algorithm>

namespace viper {
namespace capture {

namespace {

// Width and height of the bound draw framebuffer's depth attachment (0 if none or not 2D).
// `dsa`: the context has GL 4.5's direct state access, which says a texture's target.
void depthAttachmentSize(GLint& width, GLint& height, bool dsa) {
  const RealGl& g = gl();
  width = height = 0;
  // (An image attached at GL_DEPTH_STENCIL_ATTACHMENT is the depth attachment too. Asking for
  // GL_DEPTH_STENCIL_ATTACHMENT where depth and stencil differ, a stencil-only framebuffer, is an
  // error, which the program would then read from glGetError as its own.)
  const GLenum attachment = GL_DEPTH_ATTACHMENT;
  const GLint type = drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE);
  if (type == GL_NONE) return;
  const GLuint name = static_cast<GLuint>(drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME));
  if (type == GL_RENDERBUFFER) {
    const GLint prev = glInt(GL_RENDERBUFFER_BINDING);
    g.BindRenderbuffer(GL_RENDERBUFFER, name);
    g.GetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_WIDTH, &width);
    g.GetRenderbufferParameteriv(GL_RENDERBUFFER, GL_RENDERBUFFER_HEIGHT, &height);
    g.BindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(prev));
  } else if (type == GL_TEXTURE && drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_CUBE_MAP_FACE) == 0 &&
             drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_LAYERED) == GL_FALSE &&
             drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LAYER) == 0) {
    const GLint level = drawAttachmentParam(attachment, GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL);
    if (dsa) {
      // The size whatever the texture's target, without binding it (binding a 1D, rectangle or
      // array depth texture to GL_TEXTURE_2D is an error the program would read as its own).
      g.GetTextureLevelParameteriv(name, level, GL_TEXTURE_WIDTH, &width);
      g.GetTextureLevelParameteriv(name, level, GL_TEXTURE_HEIGHT, &height);
      return;
    }
    // Before GL 4.5, taken for a 2D texture: the GL cannot say a texture's target (a depth texture
    // of another target, attached at layer 0, would not bind here, and is not supported).
    const GLint prev = glInt(GL_TEXTURE_BINDING_2D);
    g.BindTexture(GL_TEXTURE_2D, name);
    g.GetTexLevelParameteriv(GL_TEXTURE_2D, level, GL_TEXTURE_WIDTH, &width);
    g.GetTexLevelParameteriv(GL_TEXTURE_2D, level, GL_TEXTURE_HEIGHT, &height);
    g.BindTexture(GL_TEXTURE_2D, static_cast<GLuint>(prev));
  }
}

// The image at `attachment` of the framebuffer bound to `target` (a program's framebuffer object).
FrameTarget::ImageRef attachedImage(GLenum target, GLenum attachment) {
  const RealGl& g = gl();
  FrameTarget::ImageRef image;
  auto param = [&](GLenum pname) {
    GLint v = 0;
    g.GetFramebufferAttachmentParameteriv(target, attachment, pname, &v);
    return v;
  };
  image.type = param(GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE);
  if (image.type != GL_TEXTURE && image.type != GL_RENDERBUFFER) {
    image.type = GL_NONE;
    return image;
  }
  image.name = static_cast<GLuint>(param(GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME));
  if (image.type == GL_TEXTURE) {
    image.level = param(GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL);
    image.layer = param(GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LAYER);
  }
  return image;
}

bool isColorAttachment(GLenum buffer) {
  return buffer >= GL_COLOR_ATTACHMENT0 && buffer <= GL_COLOR_ATTACHMENT15;
}

}  // namespace

void FrameTarget::programBlitToWindow(GLint src_x0, GLint src_y0, GLint src_x1, GLint src_y1, GLint dst_x0,
                                      GLint dst_y0, GLint dst_x1, GLint dst_y1, GLbitfield mask) {
  if (!fbo_ || program_draw_fb != 0 || program_read_fb == 0 || !(mask & GL_COLOR_BUFFER_BIT)) return;
  // The whole of the source to the whole window, one pixel for one pixel, not mirrored in x.
  auto whole = [](GLint a, GLint b, int size) { return std::min(a, b) == 0 && std::max(a, b) == size; };
  if (!whole(src_x0, src_x1, width_) || !whole(dst_x0, dst_x1, width_) || !whole(src_y0, src_y1, height_) ||
      !whole(dst_y0, dst_y1, height_) || (src_x1 > src_x0) != (dst_x1 > dst_x0)) {
    window_blit_source_ = ImageRef{};
    return;
  }
  const GLenum read_buffer = static_cast<GLenum>(glInt(GL_READ_BUFFER));
  window_blit_source_ = isColorAttachment(read_buffer) ? attachedImage(GL_READ_FRAMEBUFFER, read_buffer) : ImageRef{};
  window_blit_flipped_ = (src_y1 > src_y0) != (dst_y1 > dst_y0);
}

bool FrameTarget::isSceneCandidate() const {
  const RealGl& g = gl();
  if (g.CheckFramebufferStatus(GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return false;
  if (glInt(GL_SAMPLES) != 0) return false;  // multisampled: no read-back of its pixels
  GLint w = 0, h = 0;
  depthAttachmentSize(w, h, dsa_);
  return w == width_ && h == height_;
}

FrameTarget::ProgramFbo* FrameTarget::sceneFbo(bool clear_stale) {
  if (program_draw_fb == 0 || !fbo_) return nullptr;
  ProgramFbo& f = program_fbos_[program_draw_fb];
  if (f.checked_frame != frame_serial_) {
    f.checked_frame = frame_serial_;
    f.scene = isSceneCandidate();
    if (f.scene) {
      const GLenum first = f.program_draw_buffers.empty() ? GLenum(GL_NONE) : f.program_draw_buffers[0];
      f.color = isColorAttachment(first) ? attachedImage(GL_DRAW_FRAMEBUFFER, first) : ImageRef{};
      const RealGl& g = gl();
      if (!f.ids) {
        const GLint prev_tex = glInt(GL_TEXTURE_BINDING_2D);
        const GLint prev_unpack = glInt(GL_PIXEL_UNPACK_BUFFER_BINDING);
        g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        g.GenTextures(1, &f.ids);
        g.BindTexture(GL_TEXTURE_2D, f.ids);
        g.TexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, width_, height_, 0, GL_RG, GL_FLOAT, nullptr);
        g.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        g.BindTexture(GL_TEXTURE_2D, static_cast<GLuint>(prev_tex));
        g.BindBuffer(GL_PIXEL_UNPACK_BUFFER, static_cast<GLuint>(prev_unpack));
      }
      // Attached again whenever it is not (a new framebuffer object under a reused name).
      if (static_cast<GLuint>(drawAttachmentParam(kIdAttachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME)) != f.ids) {
        g.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, kIdAttachment, GL_TEXTURE_2D, f.ids, 0);
        f.ids_enabled = false;
        applyFboDrawBuffers(f, false);
      }
    }
  }
  if (!f.scene) return nullptr;
  if (clear_stale && !f.ids_cleared) clearFboIds(f);  // drawn into this frame before any clear
  return &f;
}

void FrameTarget::programFboDrawBuffers(GLsizei n, const GLenum* bufs) {
  ProgramFbo& f = program_fbos_[program_draw_fb];
  f.program_draw_buffers.assign(bufs, bufs + (n > 0 ? n : 0));
  applyFboDrawBuffers(f, f.scene && f.ids_wanted);
}

void FrameTarget::programFboDeleted(GLuint name) {
  auto it = program_fbos_.find(name);
  if (it == program_fbos_.end()) return;
  if (it->second.ids) gl().DeleteTextures(1, &it->second.ids);
  program_fbos_.erase(it);
}

bool FrameTarget::programOwnsIdDrawBuffer() const {
  if (program_draw_fb == 0) return false;
  auto it = program_fbos_.find(program_draw_fb);
  if (it == program_fbos_.end()) return false;
  const std::vector<GLenum>& bufs = it->second.program_draw_buffers;
  return bufs.size() > kIdDrawBuffer && bufs[kIdDrawBuffer] != GL_NONE;
}

bool FrameTarget::programFboDrawBuffer(GLuint index, GLenum& out) const {
  if (index != kIdDrawBuffer || program_draw_fb == 0) return false;
  auto it = program_fbos_.find(program_draw_fb);
  if (it == program_fbos_.end() || !it->second.ids_enabled) return false;
  const std::vector<GLenum>& bufs = it->second.program_draw_buffers;
  out = index < bufs.size() ? bufs[index] : GLenum(GL_NONE);
  return true;
}

void FrameTarget::applyFboDrawBuffers(ProgramFbo& f, bool ids) {
  const bool wanted = ids;
  std::vector<GLenum> bufs = f.program_draw_buffers;
  const bool color = !bufs.empty() && bufs[0] != GL_NONE;
  // The program draws into its own draw buffer kIdDrawBuffer (all eight in use): it keeps it, and
  // this framebuffer gets no ids.
  if (bufs.size() > kIdDrawBuffer && bufs[kIdDrawBuffer] != GL_NONE) ids = false;  // programOwnsIdDrawBuffer
  if (ids && color && f.ids) {
    if (bufs.size() <= kIdDrawBuffer) bufs.resize(kIdDrawBuffer + 1, GL_NONE);
    bufs[kIdDrawBuffer] = kIdAttachment;
  }
  gl().DrawBuffers(static_cast<GLsizei>(bufs.size()), bufs.data());
  f.ids_wanted = wanted;
  f.ids_enabled = ids && color && f.ids;
}

void FrameTarget::clearFboIds(ProgramFbo& f) {
  const RealGl& g = gl();
  const bool was_enabled = f.ids_enabled, was_wanted = f.ids_wanted;
  if (!was_enabled) applyFboDrawBuffers(f, true);
  if (f.ids_enabled) {
    static const GLfloat kZero[4] = {0, 0, 0, 0};
    GLboolean mask[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    g.GetBooleani_v(GL_COLOR_WRITEMASK, kIdDrawBuffer, mask);
    const GLboolean scissor = g.IsEnabled(GL_SCISSOR_TEST);
    if (scissor) g.Disable(GL_SCISSOR_TEST);
    g.ColorMaski(kIdDrawBuffer, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    g.ClearBufferfv(GL_COLOR, kIdDrawBuffer, kZero);
    g.ColorMaski(kIdDrawBuffer, mask[0], mask[1], mask[2], mask[3]);
    if (scissor) g.Enable(GL_SCISSOR_TEST);
    f.ids_cleared = true;
  }
  if (!was_enabled) applyFboDrawBuffers(f, was_wanted);
}

GLuint FrameTarget::sceneSource() const {
  GLuint best = 0;
  uint32_t most = 0;
  for (const auto& [name, f] : program_fbos_)
    if (f.scene && f.draws > most) best = name, most = f.draws;
  return best;
}

void FrameTarget::endFrame() {
  ++frame_serial_;
  scene_color_taken_ = scene_depth_taken_ = scene_ended_ = false;
  window_blit_source_ = ImageRef{};
  for (auto& [name, f] : program_fbos_) f.draws = 0, f.ids_cleared = false;
}

}  // namespace capture
}  // namespace viper
