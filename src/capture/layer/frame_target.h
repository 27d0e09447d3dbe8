// The interceptor's stand-in for a context's default framebuffer: color (the program's image),
// draw/primitive ids, and depth(-stencil) in the formats of the real default framebuffer.
#pragma once

#include "gl_real.h"
#include "viper/capture/shader_rewrite.h"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

namespace viper {
namespace capture {

/// Pixels read back at a swap, bottom row first as glReadPixels gives them: in the vectors, or
/// (asynchronous read-back) in a mapped pixel-pack buffer that the views point into.
struct RawImages {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;   ///< 4 bytes per pixel
  std::vector<float> depth;    ///< window depth as floats (formats other than depth24/stencil8)
  std::vector<uint32_t> depth_24_8;  ///< packed depth24/stencil8 (depth in the high 24 bits)
  std::vector<float> ids;      ///< 2 floats per pixel: draw id (index + 1), primitive id
  /// Depth and ids come from a framebuffer object of the program's that reaches the window turned
  /// upside down (FrameTarget::programBlitToWindow): their rows are top row first, the color's not.
  bool depth_ids_top_first = false;

  /// The same images in a buffer of the GL's, where set (each then replaces its vector).
  const uint8_t* rgba_view = nullptr;
  const float* depth_view = nullptr;
  const uint32_t* depth_24_8_view = nullptr;
  const float* ids_view = nullptr;
  /// The buffer's flag, true while these views may be read; releaseViews() clears it.
  std::shared_ptr<std::atomic<bool>> view_owner;

  /// Work the writer thread does before finishing the frame, off the program's thread (the Vulkan
  /// layer converts its read-back buffers into the vectors here). Null: none. Dropped, unrun, with
  /// a frame that is not written.
  std::function<void(RawImages&)> prepare;


  /// Done with the buffer: its flag cleared (it may be read into again), the views dropped.
  void releaseViews() {
    if (view_owner) view_owner->store(false);
    view_owner.reset();
    rgba_view = nullptr, depth_view = nullptr, depth_24_8_view = nullptr, ids_view = nullptr;
  }
};

/// Draw buffer index of our id attachment (the fragment location of the rewritten shaders' id
/// output), on our framebuffer and on the program's scene framebuffer objects alike.
constexpr GLuint kIdDrawBuffer = static_cast<GLuint>(kIdOutputLocation);

/// One per GL context. Methods must be called with that context current.
class FrameTarget {
 public:
  /// Creates or resizes the substitute framebuffer to `width` x `height`, matching the formats
  /// of the real default framebuffer (queried the first time).
  void ensureSize(int width, int height);
  bool ready() const { return fbo_ != 0; }
  /// The program does what the substitute cannot stand in for (the front buffer, the accumulation
  /// buffer): its image, depth and stencil so far are copied into the window's framebuffer, which
  /// it is given back (bindings, draw and read buffers as it named them), our ids leave its
  /// framebuffer objects, and this target is never made again: the context draws as without the
  /// layer, and nothing more is recorded from it.
  void giveUp();
  bool givenUp() const { return given_up_; }
  GLuint fbo() const { return fbo_; }
  int width() const { return width_; }
  int height() const { return height_; }

  /// Program-visible framebuffer bindings (0 = the default framebuffer, i.e. ours).
  GLuint program_draw_fb = 0;
  GLuint program_read_fb = 0;
  /// Draw buffers the program selected for "its" default framebuffer, as it named them (GL_BACK,
  /// GL_FRONT, GL_BACK_LEFT, GL_NONE...): what glGetIntegerv(GL_DRAW_BUFFERi) answers. Ours draws
  /// into its color attachment for any of them but GL_NONE. Set from the window's own state when
  /// the target is made (GL_BACK for a double-buffered window, GL_FRONT for a single-buffered one).
  std::vector<GLenum> program_draw_buffers{GL_BACK};
  GLenum programDrawBuffer() const { return program_draw_buffers.empty() ? GLenum(GL_NONE) : program_draw_buffers[0]; }
  /// Read buffer the program selected for it, as it named it.
  GLenum program_read_buffer = GL_BACK;
  /// The program's draw buffer `index` of its bound draw framebuffer object where ours has taken
  /// that slot for the ids (kIdDrawBuffer, ids on): what glGetIntegerv(GL_DRAW_BUFFERi) answers.
  /// False where the real answer is the program's own.
  bool programFboDrawBuffer(GLuint index, GLenum& out) const;
  /// The program's bound draw framebuffer object has a draw buffer of its own at kIdDrawBuffer
  /// (all eight in use): no ids go there.
  bool programOwnsIdDrawBuffer() const;
  /// Whether our id attachment is currently a draw buffer.
  bool ids_enabled = true;

  /// Sets the draw buffers of our framebuffer from program_draw_buffer and `ids` (ours at kIdDrawBuffer).
  void applyDrawBuffers(bool ids);
  /// Sets the read buffer of our framebuffer from program_read_buffer.
  void applyReadBuffer();

  /// An image attached to a framebuffer: a texture's level and layer, or a renderbuffer.
  struct ImageRef {
    GLint type = GL_NONE;  ///< GL_TEXTURE, GL_RENDERBUFFER, or GL_NONE (no image)
    GLuint name = 0;
    GLint level = 0, layer = 0;
    bool operator==(const ImageRef& o) const {
      return type == o.type && name == o.name && level == o.level && layer == o.layer;
    }
  };

  /// Before the program's glBlitFramebuffer (or glBlitFramebufferEXT) from its bound read
  /// framebuffer into its bound draw framebuffer: where that is the window's (ours) and the blit
  /// copies color from the whole of an image to the whole window, one pixel for one pixel, the
  /// frame's image is that image, as it is or turned upside down (wined3d presents its back buffer
  /// so); the last such blit of a frame counts. present() then reads depth and ids of a scene
  /// framebuffer object whose color image that is the same way up as the color.
  void programBlitToWindow(GLint src_x0, GLint src_y0, GLint src_x1, GLint src_y1, GLint dst_x0, GLint dst_y0,
                           GLint dst_x1, GLint dst_y1, GLbitfield mask);

  /// A framebuffer object of the program's that may hold its scene (rendered off screen, then
  /// composited into the default framebuffer): complete, single-sampled, with a depth attachment,
  /// the size of the default framebuffer. Draws into it write ids into a texture of ours attached
  /// at kIdAttachment (draw buffer kIdDrawBuffer), and the one that took the most draws in a frame gives that frame's depth
  /// and ids (the color stays the program's final image).
  struct ProgramFbo {
    uint64_t checked_frame = ~0ull;  ///< frame serial of the last check
    bool scene = false;              ///< passed the check
    GLuint ids = 0;                  ///< our id texture (RG32F)
    std::vector<GLenum> program_draw_buffers{GL_COLOR_ATTACHMENT0};
    bool ids_wanted = false;         ///< last asked for: the drawing program writes ids
    bool ids_enabled = false;        ///< our attachment is a draw buffer now (wanted, and color drawn)
    bool ids_cleared = false;        ///< our attachment was cleared this frame
    uint32_t draws = 0;              ///< draws recorded into it this frame
    ImageRef color;                  ///< the image of its first draw buffer at this frame's check
  };
  static constexpr GLenum kIdAttachment = GL_COLOR_ATTACHMENT7;
  /// The program's bound draw framebuffer object if it may hold the scene (checked once a frame;
  /// our id attachment added, and cleared for the frame unless `clear_stale` is false), else nullptr.
  ProgramFbo* sceneFbo(bool clear_stale = true);
  /// The program's glDrawBuffer(s) on its bound framebuffer object: kept, and applied with our id
  /// attachment as draw buffer kIdDrawBuffer where it has one enabled.
  void programFboDrawBuffers(GLsizei n, const GLenum* bufs);
  /// Sets the draw buffers of the bound program framebuffer f: the program's, with ours at
  /// kIdDrawBuffer if `ids`.
  void applyFboDrawBuffers(ProgramFbo& f, bool ids);
  /// Our id attachment on or off as a draw buffer of the scene's framebuffer: the program's
  /// `scene_fbo`, or ours (the default framebuffer) when null. Applied only when it changes.
  void wantIds(ProgramFbo* scene_fbo, bool ids) {
    if (scene_fbo) {
      if (scene_fbo->ids_wanted != ids) applyFboDrawBuffers(*scene_fbo, ids);
    } else if (ids_enabled != ids) {
      applyDrawBuffers(ids);
    }
  }
  /// The program deleted its framebuffer object `name`: our id texture for it goes too.
  void programFboDeleted(GLuint name);
  /// After the program cleared color or depth of its bound framebuffer f: our ids back to 0.
  void clearFboIds(ProgramFbo& f);

  /// Keeps a copy of the program's image as it is now (before its first 2D overlay draw of the
  /// frame); present() then reads the frame's color from that copy. Once a frame.
  void snapshotSceneColor() { snapshotScene(false); }
  /// The scene of this frame ends now (the program clears depth after drawing it, to draw a
  /// first-person hand or 3D HUD items over it): color and depth are kept as they are, and later
  /// draws of the frame are neither recorded nor given ids (sceneEnded()).
  void endScene() {
    snapshotScene(true);
    scene_ended_ = true;
  }
  bool sceneEnded() const { return scene_ended_; }

  /// Copies the program's image to the real default framebuffer (unless `to_surface` is false:
  /// pbuffers, whose content the program can only read through GL, which reads ours) and reads
  /// color, and depth and ids from the default framebuffer or the scene's framebuffer object.
  /// Restores every binding and state it touches. Without `read_back` (frames not captured) only
  /// the copy to the surface happens.
  void present(RawImages& out, bool to_surface, bool read_back = true);
  /// Like present(), but reads into a free pixel-pack buffer of this target's (persistently
  /// mapped) without waiting for the GPU: `out`'s views point there, valid once `fence` has
  /// signalled, until out.releaseViews(). Returns false, having done nothing, when no buffer is
  /// free or the context lacks glBufferStorage (GL 4.4 / ARB_buffer_storage): call present().
  bool presentAsync(RawImages& out, bool to_surface, GLsync& fence);
  /// Pixel-pack buffers for presentAsync (16 bytes a pixel each): frames being copied by the GPU,
  /// queued for the writers or being read by them. Set before the first presentAsync.
  size_t pack_buffer_count = 3;
  /// Seconds spent in the glReadPixels calls of present() and presentAsync() so far.
  double readSeconds() const { return read_seconds_; }
  /// Whether a writer thread may still read one of this target's pixel-pack buffers.
  bool packBuffersInUse() const;

 private:
  void queryDefaultFormats();
  void destroy();
  bool isSceneCandidate() const;  // the bound draw framebuffer object
  // The scene's framebuffer object of this frame (most recorded draws), 0 for ours.
  GLuint sceneSource() const;
  void readDepthAndIds(GLuint fb, GLenum id_buffer, RawImages& out);
  void endFrame();
  // Asynchronous read-back: buffers mapped for reading for as long as they live.
  struct PackBuffer {
    GLuint name = 0;
    const uint8_t* mapped = nullptr;
    std::shared_ptr<std::atomic<bool>> in_use = std::make_shared<std::atomic<bool>>(false);
  };
  std::vector<PackBuffer> pack_buffers_;
  int async_supported_ = -1;  // -1: not checked yet
  double read_seconds_ = 0.0;
  void presentInto(RawImages& out, bool to_surface, bool read_back, PackBuffer* into);

  std::unordered_map<GLuint, ProgramFbo> program_fbos_;
  // The image the last whole-window blit of this frame copied into the window, and whether upside
  // down (programBlitToWindow); type GL_NONE: none.
  ImageRef window_blit_source_;
  bool window_blit_flipped_ = false;
  void snapshotScene(bool with_depth);
  GLuint scene_color_fbo_ = 0, scene_color_ = 0, scene_depth_ = 0;  // snapshotScene()
  bool scene_color_taken_ = false, scene_depth_taken_ = false, scene_ended_ = false;
  uint64_t frame_serial_ = 0;

  GLuint fbo_ = 0;
  GLuint color_ = 0, ids_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
  bool formats_known_ = false;
  bool given_up_ = false;
  bool dsa_ = false;  ///< GL 4.5 (direct state access)
  GLenum window_draw_buffer_ = GL_BACK;  ///< the window's draw buffer when the target was made
  GLenum color_format_ = GL_RGBA8;
  GLenum depth_format_ = GL_DEPTH24_STENCIL8;  // 0 = no depth attachment
  GLenum depth_attachment_ = GL_DEPTH_STENCIL_ATTACHMENT;
};

}  // namespace capture
}  // namespace viper
