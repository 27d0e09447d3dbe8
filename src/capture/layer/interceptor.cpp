#include "interceptor.h"

#include "capture_settings.h"

#include <cstring>

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace viper {
namespace capture {

namespace {

thread_local FrameTarget* t_target = nullptr;
thread_local ContextState* t_context = nullptr;

Interceptor* g_instance = nullptr;

// Closes the stream when the program exits normally (library destructors run after main).
__attribute__((destructor)) void closeAtExit() {
  if (g_instance) g_instance->shutdown();
}

// With asynchronous read-back, the frames still in the GL's buffers are handed over, and the
// writers finish reading those buffers, while the driver still stands: atexit handlers run in the
// reverse order of their registration, so one registered after the driver's own (at the first
// asynchronous read) runs before the driver tears down its mappings (NVIDIA's does, before any
// library destructor runs).
void shutdownAtExit() {
  if (g_instance) g_instance->shutdown();
}

}  // namespace

Interceptor& Interceptor::instance() {
  // Never destroyed: the program may still call GL while static objects are torn down.
  static Interceptor* inst = (g_instance = new Interceptor);
  return *inst;
}

Interceptor::Interceptor() {
  CaptureSettings settings;
  try {
    settings = readCaptureSettings();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[viper capture] capture disabled: %s\n", e.what());
    return;
  }
  output_path_ = settings.output;
  if (output_path_.empty()) return;  // preloaded without a destination: pure pass-through
  condition_ = settings.condition;
  frame_limit_ = settings.frame_limit;
  fixed_fps_ = settings.fixed_fps;
  skip_frames_ = settings.skip_frames;
  start_on_scene_ = settings.start_on_scene;
  try {
    if (settings.profile_path.empty()) profile_.source = "<default>";
    else profile_ = loadCaptureProfile(settings.profile_path);
    const ProgramProfile& fixed = *profile_.matchFixedFunction();
    fixed_function_.key = kFixedFunctionProgramKey;
    fixed_function_.overlay = fixed.overlay;
    fixed_function_.matrix_stack = !fixed.matrix_stack.empty();
    fixed_function_.stack_push_world = fixed.matrix_stack == "push_world";
    fixed_function_.vertex_array_position = true;
    combines_ = profile_.combinesMatrices();
    // Without the stack split, the stack's model-view is a combined matrix where the profile has them.
    fixed_function_.combined = combines_ && !fixed_function_.matrix_stack;
    fixed_function_.world_space = fixed.world_space;
    fixed_function_.expected_matrices =
        kHasProjection | (fixed_function_.matrix_stack || fixed_function_.combined ? kHasWorld | kHasView : 0);
    settings.header.profile = profile_.source;
    // Asynchronous read-back (the capture launcher's --readback): a GPU copies the frame while the
    // program goes on; with a CPU renderer it is the same copy, later, so `auto` (the default)
    // reads asynchronously except on software renderers.
    async_readback_ = settings.readback == "async";
    readback_decided_ = settings.readback != "auto";
    // One layer writes the stream (a program may load both APIs): the Vulkan layer's, if it has.
    if (const char* claimed = std::getenv("VIPER_CAPTURE_CLAIMED_BY"))
      if (std::string(claimed) != "opengl")
        throw std::runtime_error(std::string("the capture is written by the ") + claimed + " layer");
    sink_.reset(new FrameSink(output_path_, settings.header, settings.zstd_level, settings.writer_threads));
    setenv("VIPER_CAPTURE_CLAIMED_BY", "opengl", 1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[viper capture] capture disabled: %s\n", e.what());
    return;
  }
  start_s_ = monotonicSeconds();
  enabled_ = true;
}

void Interceptor::pushPending(size_t keep) {
  while (pending_frames_.size() > keep) {
    PendingFrame& p = pending_frames_.front();
    if (p.target != target()) break;  // another context's (handed over when it was left)
    // Flushed, so the wait ends; a second per try, as long as the GPU needs.
    while (gl().ClientWaitSync(p.fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull) == GL_TIMEOUT_EXPIRED) {
    }
    gl().DeleteSync(p.fence);
    sink_->push(std::move(p.frame), std::move(p.raw));
    pending_frames_.pop_front();
  }
}

void Interceptor::resizeTarget(FrameTarget& t, int width, int height) {
  if (width != t.width() || height != t.height()) pushPending(0);  // resizing unmaps the read-back buffers
  t.ensureSize(width, height);
}

void Interceptor::beforeMakeCurrent() {
  FrameTarget* t = target();
  if (!enabled_ || !t) return;
  // The pending frames are shared with the swaps of other threads' contexts.
  std::lock_guard<std::mutex> lifecycle(lifecycle_mutex_);
  if (pending_frames_.empty()) return;
  pushPending(0);
  // The context may be destroyed once it is released: no writer may read its buffers then.
  while (t->packBuffersInUse()) {
    timespec pause{0, 1000000};
    nanosleep(&pause, nullptr);
  }
}

void Interceptor::shutdown() {
  std::lock_guard<std::mutex> lifecycle(lifecycle_mutex_);
  if (!enabled_ || closed_) return;
  // From here on nothing is written; the hooks go on as before (the framebuffer substituted, ids
  // drawn), so that a program whose other threads still draw meanwhile draws as it did: switching
  // them back to its own framebuffer made llvmpipe compile new shader variants while exit() tore
  // LLVM down (a crash, 5-9 times in 20).
  closed_ = true;
  if (sink_ && !pending_frames_.empty()) {
    pushPending(0);  // the current context's, if it is still current on this thread
    if (!pending_frames_.empty())
      std::fprintf(stderr, "[viper capture] %zu frames read asynchronously were lost: their context was not current on the "
                   "thread that ended the program\n",
                   pending_frames_.size());
    pending_frames_.clear();
  }
  if (sink_) sink_->close();
  if (stats_.frames && std::getenv("VIPER_CAPTURE_STATS")) {
    const double n = static_cast<double>(stats_.frames);
    std::fprintf(stderr,
                 "[viper capture] %llu frames; per frame: read-back %.2f ms (deformed vertices %.2f, pixel reads %.2f), "
                 "waiting for the writer %.2f ms, writer threads %.2f ms (%d threads, summed)\n",
                 static_cast<unsigned long long>(stats_.frames), stats_.present_s / n * 1e3, stats_.deform_s / n * 1e3,
                 stats_.pixel_reads_s / n * 1e3,
                 stats_.push_wait_s / n * 1e3, sink_->busySeconds() / n * 1e3, sink_->threads());
    if (async_readback_)
      std::fprintf(stderr, "[viper capture] asynchronous read-back: %llu of %llu frames read synchronously (no buffer free)\n",
                   static_cast<unsigned long long>(stats_.synchronous_reads), static_cast<unsigned long long>(stats_.frames));
  }
}

FrameTarget* Interceptor::target() { return t_target; }

ContextState& Interceptor::cx() {
  if (t_context) return *t_context;
  thread_local ContextState none;  // no context current: what the thread's calls set goes nowhere
  return none;
}

void Interceptor::onMakeCurrent(void* context, int width, int height) {
  if (enabled_ && !exit_hook_) {
    // Shut down before the driver's own exit handlers (registered when the program opened its
    // display, so run after this one): a thread that calls exit() while another renders then
    // tears nothing down under the renderer for longer than the program alone does.
    std::lock_guard<std::mutex> lock(lifecycle_mutex_);
    if (!exit_hook_) exit_hook_ = std::atexit(&shutdownAtExit) == 0;
  }
  ContextState* previous = t_context;
  ContextState* c = nullptr;
  bool es_context = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (previous && previous->target.get() != nullptr) {
      previous->current = false;
      if (previous->destroyed) {  // destroyed while current: its objects are gone now
        for (auto it = contexts_.begin(); it != contexts_.end(); ++it)
          if (it->second.get() == previous) {
            contexts_.erase(it);
            break;
          }
      }
    }
    if (context) {
      std::unique_ptr<ContextState>& slot = contexts_[context];
      if (!slot) {
        slot.reset(new ContextState);
        slot->target.reset(new FrameTarget);
        // OpenGL ES: its shaders are not rewritten, and the substitute (desktop formats and
        // queries) would fail there: the context keeps its own framebuffer.
        const GLubyte* version = gl().GetString ? gl().GetString(GL_VERSION) : nullptr;
        if (version && std::strncmp(reinterpret_cast<const char*>(version), "OpenGL ES", 9) == 0) {
          slot->target->giveUp();
          es_context = true;
        }
        // Asynchronous read-back: one buffer being copied, one waiting for its turn, one per
        // writer thread and the sink's queue of two.
        if (sink_) slot->target->pack_buffer_count = std::min<size_t>(12, static_cast<size_t>(sink_->threads()) + 4);
      }
      c = slot.get();
      c->current = true;
    }
  }
  t_context = c;
  t_target = c ? c->target.get() : nullptr;
  if (es_context) logOnce("an OpenGL ES context: the layer leaves it as it is and records nothing from it");
  if (!c || c->target->givenUp()) return;  // (no query: some are errors in OpenGL ES)
  {
    // The same context made current again on a surface of another size keeps its pending frames.
    std::lock_guard<std::mutex> lifecycle(lifecycle_mutex_);
    resizeTarget(*t_target, width, height);
  }
  GLint program = 0;
  gl().GetIntegerv(GL_CURRENT_PROGRAM, &program);
  c->current_program = static_cast<GLuint>(program);
  c->current_program_info = nullptr;
  c->blend0_enabled = gl().IsEnabledi(GL_BLEND, 0);
  c->blend_dirty = true;
  c->base_instance_draws = glVersionAtLeast(4, 2);
  if (!c->fixed_function_noted) noteFixedFunction(*c);
}

void Interceptor::contextDestroyed(void* context) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = contexts_.find(context);
  if (it == contexts_.end()) return;
  if (it->second->current) it->second->destroyed = true;  // EGL destroys it when it is released
  else contexts_.erase(it);
}

void Interceptor::beforeSwap(int width, int height, bool offscreen) {
  FrameTarget* t = target();
  if (!enabled_ || !t || !t->ready()) return;
  std::unique_lock<std::mutex> lifecycle(lifecycle_mutex_);
  oneStackView();
  resolveCombined();
  // Frames before the scene (menus, loading screens) are shown but not written: skipped by count,
  // or until a recorded draw has the camera's matrices. After shutdown (exit() called by another
  // thread while this one renders on) nothing is written, and the program still draws as before.
  bool write = !closed_ && frame_number_ >= skip_frames_;
  if (write && start_on_scene_ && frames_written_ == 0) {
    write = false;
    for (const DrawRecord& d : cx().frame.draws)
      if ((d.matrix_flags & kHasView) && (d.matrix_flags & kHasProjection)) write = true;
  }
  if (!write) {
    RawImages none;
    t->present(none, !offscreen, /*read_back=*/false);
    readDeformed();
    ++frame_number_;
    std::vector<MeshRecord> meshes = std::move(cx().frame.new_meshes);  // sent once: with the next written frame
    cx().frame = CaptureFrame();
    cx().frame.new_meshes = std::move(meshes);
    cx().last_mesh = false;
    resizeTarget(*t, width, height);
    return;
  }
  if (!readback_decided_) {
    const GLubyte* renderer = gl().GetString ? gl().GetString(GL_RENDERER) : nullptr;
    const std::string name = renderer ? reinterpret_cast<const char*>(renderer) : "";
    async_readback_ = !name.empty();
    for (const char* software : {"llvmpipe", "softpipe", "SWR", "Software Rasterizer", "swrast"})
      if (name.find(software) != std::string::npos) async_readback_ = false;
    readback_decided_ = true;
    if (std::getenv("VIPER_CAPTURE_STATS"))
      std::fprintf(stderr, "[viper capture] renderer %s: %s read-back\n", name.c_str(),
                   async_readback_ ? "asynchronous" : "synchronous");
  }
  RawImages raw = sink_->recycledRaw();
  const double t0 = monotonicSeconds();
  // Deformed vertices first: reading them waits for the GPU to finish the frame, and must not
  // wait for the copies of the images that an asynchronous read-back leaves running.
  readDeformed();
  stats_.deform_s += monotonicSeconds() - t0;
  GLsync fence = nullptr;
  // Asynchronous: into a free pixel-pack buffer (none free: the oldest pending frame is handed
  // over first; still none: read synchronously, after the pending frames).
  bool async = async_readback_ && t->presentAsync(raw, !offscreen, fence);
  if (async_readback_ && !async && !pending_frames_.empty()) {
    pushPending(0);
    async = t->presentAsync(raw, !offscreen, fence);
  }
  if (!async) t->present(raw, !offscreen);
  if (async_readback_ && !async) ++stats_.synchronous_reads;
  const double t1 = monotonicSeconds();
  cx().frame.number = frame_number_++;
  // A program that advances a fixed time step per frame (as the test scene and the world do) is
  // stamped with that step, not with how fast it happened to render.
  cx().frame.time_s = fixed_fps_ > 0.0 ? static_cast<double>(cx().frame.number) / fixed_fps_ : monotonicSeconds() - start_s_;
  cx().frame.condition = condition_;
  if (async) {
    // Registered again (shutdown runs once): handlers run in the reverse order of registration, and
    // a driver may register its own after the first make-current (NVIDIA's unmaps the buffers).
    if (!async_exit_hook_) async_exit_hook_ = std::atexit(&shutdownAtExit) == 0;
    pending_frames_.push_back(PendingFrame{t, fence, std::move(cx().frame), std::move(raw)});
    // The frame before this one is handed over (its copy is done by now unless the GPU lags a
    // whole frame); this one stays in the GL's buffer while the GPU copies it.
    pushPending(1);
  } else {
    sink_->push(std::move(cx().frame), std::move(raw));
  }
  cx().frame = CaptureFrame();
  stats_.present_s += t1 - t0;
  stats_.pixel_reads_s = t->readSeconds();
  stats_.push_wait_s += monotonicSeconds() - t1;
  ++stats_.frames;
  cx().last_mesh = false;
  if (mesh_cache_.size() > 8192) mesh_cache_.clear();  // streamed geometry: keep memory bounded
  resizeTarget(*t, width, height);
  ++frames_written_;
  if (frame_limit_ && frames_written_ >= frame_limit_) {
    std::fprintf(stderr, "[viper capture] captured %llu frames, stopping the program\n",
                 static_cast<unsigned long long>(frames_written_));
    lifecycle.unlock();
    shutdown();
    // Not exit(): the program's static destructors would run on this (its render) thread while its
    // other threads still use what they destroy (Minetest crashed so). The stream is closed; flush
    // the program's stdio and end without running anything else of it.
    std::fflush(nullptr);
    std::_Exit(0);
  }
}

void Interceptor::bindFramebuffer(GLenum target_enum, GLuint fb) {
  FrameTarget* t = target();
  if (!t || !t->ready()) return gl().BindFramebuffer(target_enum, fb);
  if (target_enum == GL_FRAMEBUFFER || target_enum == GL_DRAW_FRAMEBUFFER) t->program_draw_fb = fb;
  if (target_enum == GL_FRAMEBUFFER || target_enum == GL_READ_FRAMEBUFFER) t->program_read_fb = fb;
  gl().BindFramebuffer(target_enum, fb ? fb : t->fbo());
}

void Interceptor::blitFramebuffer(GLint src_x0, GLint src_y0, GLint src_x1, GLint src_y1, GLint dst_x0,
                                  GLint dst_y0, GLint dst_x1, GLint dst_y1, GLbitfield mask) {
  FrameTarget* t = target();
  if (t && t->ready()) t->programBlitToWindow(src_x0, src_y0, src_x1, src_y1, dst_x0, dst_y0, dst_x1, dst_y1, mask);
}

void Interceptor::framebuffersDeleted(GLsizei n, const GLuint* names) {
  FrameTarget* t = target();
  if (!t || !t->ready() || !names) return;
  for (GLsizei k = 0; k < n; ++k) {
    if (names[k] == 0) continue;
    if (t->program_draw_fb == names[k]) {
      t->program_draw_fb = 0;
      gl().BindFramebuffer(GL_DRAW_FRAMEBUFFER, t->fbo());
    }
    if (t->program_read_fb == names[k]) {
      t->program_read_fb = 0;
      gl().BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo());
    }
    t->programFboDeleted(names[k]);
  }
}

namespace {

// The window's colour buffers that the substitute stands for: its back buffer (and none).
bool substituteHas(GLenum buffer) { return buffer == GL_NONE || buffer == GL_BACK || buffer == GL_BACK_LEFT; }

}  // namespace

void Interceptor::giveUp(const char* why) {
  FrameTarget* t = target();
  if (!t || !t->ready()) return;
  t->giveUp();
  logOnce(std::string("a context ") + why +
          ": the layer gives it its window's framebuffer back, and records nothing more from it");
}

void Interceptor::accum(GLenum op, GLfloat value) {
  if (FrameTarget* t = target(); t && t->ready() && t->program_draw_fb == 0 && t->program_read_fb == 0)
    giveUp("uses the accumulation buffer");
  gl().Accum(op, value);
}

void Interceptor::drawBuffer(GLenum buf) {
  FrameTarget* t = target();
  if (t && t->ready() && t->program_draw_fb == 0 && !substituteHas(buf))
    giveUp("draws into its window's front buffer");
  if (!t || !t->ready()) return gl().DrawBuffer(buf);
  if (t->program_draw_fb != 0) return t->programFboDrawBuffers(1, &buf);
  t->program_draw_buffers.assign(1, buf);
  t->applyDrawBuffers(t->ids_enabled);
}

void Interceptor::drawBuffers(GLsizei n, const GLenum* bufs) {
  FrameTarget* t = target();
  if (t && t->ready() && t->program_draw_fb == 0 && bufs)
    for (GLsizei k = 0; k < n; ++k)
      if (!substituteHas(bufs[k])) {
        giveUp("draws into its window's front buffer");
        break;
      }
  if (!t || !t->ready()) return gl().DrawBuffers(n, bufs);
  if (t->program_draw_fb != 0) return t->programFboDrawBuffers(n, bufs);
  t->program_draw_buffers.assign(bufs, bufs + (n > 0 ? n : 0));
  t->applyDrawBuffers(t->ids_enabled);
}

void Interceptor::readBuffer(GLenum buf) {
  FrameTarget* t = target();
  if (t && t->ready() && t->program_read_fb == 0 && !substituteHas(buf))
    giveUp("reads its window's front buffer");
  if (!t || !t->ready() || t->program_read_fb != 0) return gl().ReadBuffer(buf);
  t->program_read_buffer = buf;
  t->applyReadBuffer();
}

void Interceptor::clear(GLbitfield mask) {
  FrameTarget* t = target();
  if ((mask & VIPER_GL_ACCUM_BUFFER_BIT) && t && t->ready() && t->program_draw_fb == 0) {
    giveUp("clears the accumulation buffer");
    return gl().Clear(mask);
  }
  if (t && t->ready() && t->program_draw_fb != 0) {
    gl().Clear(mask);
    // A new color or depth image in a framebuffer that may hold the scene: its ids start at 0.
    if (mask & (GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT))
      if (FrameTarget::ProgramFbo* f = t->sceneFbo(/*clear_stale=*/false)) t->clearFboIds(*f);
    return;
  }
  // A depth-only clear after the scene's draws, for a hand or HUD items drawn over it.
  if (t && t->ready() && profile_.depth_clear_ends_scene && (mask & GL_DEPTH_BUFFER_BIT) &&
      !(mask & GL_COLOR_BUFFER_BIT) && !cx().frame.draws.empty() && !t->sceneEnded())
    t->endScene();
  gl().Clear(mask);
  // A new image in the default framebuffer: ids start at 0 (no draw).
  if (t && t->ready() && (mask & GL_COLOR_BUFFER_BIT)) clearDefaultIds(*t);
}

void Interceptor::clearDefaultIds(FrameTarget& t) {
  static const GLfloat kZero[4] = {0, 0, 0, 0};
  const bool was_enabled = t.ids_enabled;
  if (!was_enabled) t.applyDrawBuffers(true);
  if (!cx().ids_write) {  // the clear honours the write mask a preceding effect draw left
    gl().ColorMaski(kIdDrawBuffer, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    cx().ids_write = true;
  }
  gl().ClearBufferfv(GL_COLOR, kIdDrawBuffer, kZero);
  if (!was_enabled) t.applyDrawBuffers(false);
}

void Interceptor::clearBuffer(GLenum buffer, GLint drawbuffer) {
  FrameTarget* t = target();
  if (!t || !t->ready()) return;
  // The program cleared its image (color buffer 0) or depth: ids there start at 0 (no draw).
  const bool image = (buffer == GL_COLOR && drawbuffer == 0) || buffer == GL_DEPTH || buffer == GL_DEPTH_STENCIL;
  if (!image) return;
  if (t->program_draw_fb != 0) {
    if (FrameTarget::ProgramFbo* f = t->sceneFbo(/*clear_stale=*/false)) t->clearFboIds(*f);
    return;
  }
  clearDefaultIds(*t);
}

namespace {

// State that belongs to the bound framebuffer and that the window's default framebuffer answers
// differently from ours: the pixel format and the kind of window (GL 4.6 compatibility profile,
// tables 23.73 and 23.74 "Framebuffer dependent values", and the implementation's preferred read
// format).
bool windowDependent(GLenum pname) {
  switch (pname) {
    case 0x0C00:  // GL_AUX_BUFFERS
    case 0x0C30:  // GL_INDEX_MODE
    case 0x0C31:  // GL_RGBA_MODE
    case GL_DOUBLEBUFFER: case GL_STEREO: case GL_SAMPLE_BUFFERS: case GL_SAMPLES:
    case GL_IMPLEMENTATION_COLOR_READ_FORMAT: case GL_IMPLEMENTATION_COLOR_READ_TYPE:
    case 0x0D51:                                  // GL_INDEX_BITS
    case 0x0D52: case 0x0D53: case 0x0D54: case 0x0D55:  // GL_RED_BITS .. GL_ALPHA_BITS
    case 0x0D56: case 0x0D57:                     // GL_DEPTH_BITS, GL_STENCIL_BITS
    case 0x0D58: case 0x0D59: case 0x0D5A: case 0x0D5B:  // GL_ACCUM_RED_BITS .. GL_ACCUM_ALPHA_BITS
    case 0x8DBA:                                  // GL_FRAMEBUFFER_SRGB_CAPABLE_EXT
      return true;
    default:
      return false;
  }
}

}  // namespace

bool Interceptor::beginWindowQuery(GLenum pname) {
  FrameTarget* t = target();
  if (!t || !t->ready() || !windowDependent(pname)) return false;
  if (t->program_draw_fb != 0 && t->program_read_fb != 0) return false;
  if (t->program_draw_fb == 0) gl().BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  if (t->program_read_fb == 0) gl().BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  return true;
}

bool Interceptor::beginWindowFramebufferQuery(GLenum target_enum) {
  FrameTarget* t = target();
  if (!t || !t->ready()) return false;
  const bool read = target_enum == GL_READ_FRAMEBUFFER;
  if ((read ? t->program_read_fb : t->program_draw_fb) != 0) return false;
  gl().BindFramebuffer(read ? GL_READ_FRAMEBUFFER : GL_DRAW_FRAMEBUFFER, 0);
  return true;
}

void Interceptor::endWindowQuery() {
  FrameTarget* t = target();
  gl().BindFramebuffer(GL_DRAW_FRAMEBUFFER, t->program_draw_fb ? t->program_draw_fb : t->fbo());
  gl().BindFramebuffer(GL_READ_FRAMEBUFFER, t->program_read_fb ? t->program_read_fb : t->fbo());
}

bool Interceptor::overrideQuery(GLenum pname, GLint64& value) {
  if (pname == GL_NUM_PROGRAM_BINARY_FORMATS && enabled_) return value = 0, true;  // see programBinary
  FrameTarget* t = target();
  if (!t || !t->ready()) return false;
  switch (pname) {
    case GL_DRAW_FRAMEBUFFER_BINDING: return value = t->program_draw_fb, true;
    case GL_READ_FRAMEBUFFER_BINDING: return value = t->program_read_fb, true;
    case GL_READ_BUFFER:
      if (t->program_read_fb != 0) return false;
      return value = t->program_read_buffer, true;
    default: break;
  }
  GLuint index = 0;
  if (pname == GL_DRAW_BUFFER) index = 0;
  else if (pname >= GL_DRAW_BUFFER0 && pname <= GL_DRAW_BUFFER15) index = pname - GL_DRAW_BUFFER0;
  else return false;
  if (t->program_draw_fb == 0) {
    const std::vector<GLenum>& bufs = t->program_draw_buffers;
    return value = index < bufs.size() ? bufs[index] : GLenum(GL_NONE), true;
  }
  GLenum program_buffer = GL_NONE;
  if (!t->programFboDrawBuffer(index, program_buffer)) return false;
  return value = program_buffer, true;
}

void Interceptor::colorMaskChanged() {
  FrameTarget* t = target();
  if (!t || !t->ready()) return;
  const GLboolean m = cx().ids_write ? GL_TRUE : GL_FALSE;
  gl().ColorMaski(kIdDrawBuffer, m, m, m, m);
}

void Interceptor::blendStateChanged(bool blend_enabled_known, bool blend_enabled) {
  if (blend_enabled_known) cx().blend0_enabled = blend_enabled;
  cx().blend_dirty = true;
}

}  // namespace capture
}  // namespace viper
