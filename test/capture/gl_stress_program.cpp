// OpenGL 4.5 core stress program for the capture layer: what real engines do and the other test
// programs do not, one scenario at a time (stress_scene.h says what each draws where):
//   mdi          glMultiDrawElementsIndirect (two commands) and a base-instance draw, instanced
//                attributes (divisor 1);
//   persistent   vertices in a glBufferStorage persistent + coherent mapping, rewritten every frame
//                into one of three regions, each fenced (glFenceSync / glClientWaitSync);
//   ubo_tbo      view and projection in a uniform buffer, world and colour in a texture buffer;
//   binary       glGetProgramBinary, then glProgramBinary into a new program (linked from source
//                where the binary is refused, as the GL allows);
//   threads      a shared context on a second thread uploads each frame's vertices and draws into
//                a framebuffer object of its own while the main thread draws the previous frame's
//                upload; mid-frame the main thread draws in a third, unshared context and returns;
//   destroy      mid-frame (frame 2), the context and its surface are destroyed and made again,
//                and the frame is drawn again from the start;
//   exit_thread  a second thread calls exit() while the main thread is in the middle of a frame;
//   all          each of them in turn (a fresh context each).
// Every GL call is followed by glGetError: an error the program did not cause ends it (exit 3).
// In frame 1 it causes one itself (glEnable of a bad enum) and checks after the frame's calls
// that glGetError still reports exactly that one.
//   gl_stress_program --scenario NAME [--out FILE] [--frames N] [--draw-through-exit 1]
// --draw-through-exit 1 (exit_thread): the main thread draws on while exit() runs, unchecked.
// --out: the program's own read-back of its last frame (RGBA, bottom row first). Exit 0.
// Display: Mesa's surfaceless platform, else the first EGL device (a GPU driver without Mesa);
// pbuffers of 64x64 (stress_scene.h). Prints the renderer.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include "gl_common/sanitizer_options.h"
#include "stress_scene.h"

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ss = viper::stress_scene;

namespace {

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "gl_stress_program: %s\n", what.c_str());
  std::fflush(stderr);
  std::_Exit(1);
}

// ---- glGetError after every call ----

/// The error the program caused on purpose and has not read yet (checks wait for it).
thread_local GLenum t_provoked = GL_NO_ERROR;
/// exit_thread: the other thread is about to call exit().
std::atomic<bool> g_exiting{false};
/// --draw-through-exit 1: the main thread draws on while exit() runs (and stops checking).
bool g_draw_through_exit = false;

void check(const char* what, int line) {
  if (t_provoked != GL_NO_ERROR || (g_draw_through_exit && g_exiting)) return;
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    std::fprintf(stderr, "gl_stress_program: GL error 0x%04x after %s (line %d), not caused by the program\n", e, what,
                 line);
    std::fflush(stderr);
    std::_Exit(3);
  }
}
template <typename T>
T checked(T value, const char* what, int line) {
  check(what, line);
  return value;
}
#define GL(call) ((call), check(#call, __LINE__))
#define GLV(call) checked((call), #call, __LINE__)

/// An error of the program's own: glEnable of an enum that is none.
void provokeError() {
  glEnable(0x1234);
  t_provoked = GL_INVALID_ENUM;
}
/// After the calls that followed: the program's error is what glGetError reports, and only it.
void expectProvokedError() {
  const GLenum e = glGetError();
  if (e != t_provoked) die("the program's own GL error changed: expected 0x500, read 0x" + std::to_string(e));
  t_provoked = GL_NO_ERROR;
  check("reading the program's own error", __LINE__);
}

// ---- EGL ----

EGLDisplay g_display = EGL_NO_DISPLAY;
EGLConfig g_config = nullptr;

/// Initialised, with an RGBA8 + depth 24 pbuffer config for desktop OpenGL in g_config.
bool tryDisplay(EGLDisplay display) {
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr)) return false;
  const EGLint attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8,
                          EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_NONE};
  EGLint n = 0;
  if (!eglChooseConfig(display, attrs, &g_config, 1, &n) || n == 0) return false;
  g_display = display;
  return true;
}

/// Mesa's surfaceless platform, else (a GPU driver without Mesa's platforms) the first EGL device.
void initDisplay() {
  if (g_display != EGL_NO_DISPLAY) return;
  if (!tryDisplay(eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr))) {
    const auto query = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[4];
    EGLint count = 0;
    if (!query || !query(4, devices, &count) || count == 0 ||
        !tryDisplay(eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr)))
      die("no EGL display");
  }
  eglBindAPI(EGL_OPENGL_API);
}

struct Surface {
  EGLSurface surface = EGL_NO_SURFACE;
  EGLContext context = EGL_NO_CONTEXT;
};

Surface makeSurface(int size, EGLContext share = EGL_NO_CONTEXT) {
  initDisplay();
  eglBindAPI(EGL_OPENGL_API);
  const EGLint surface_attrs[] = {EGL_WIDTH, size, EGL_HEIGHT, size, EGL_NONE};
  const EGLint context_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  Surface s;
  s.surface = eglCreatePbufferSurface(g_display, g_config, surface_attrs);
  s.context = eglCreateContext(g_display, g_config, share, context_attrs);
  if (s.surface == EGL_NO_SURFACE || s.context == EGL_NO_CONTEXT) die("no EGL pbuffer or GL 4.5 context");
  return s;
}
void makeCurrent(const Surface& s) {
  if (!eglMakeCurrent(g_display, s.surface, s.surface, s.context)) die("eglMakeCurrent failed");
  static bool said = false;
  if (!said) {
    said = true;
    std::printf("renderer %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  }
}
void destroy(Surface& s) {
  if (!eglMakeCurrent(g_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT)) die("eglMakeCurrent(none) failed");
  eglDestroyContext(g_display, s.context);
  eglDestroySurface(g_display, s.surface);
  s = Surface();
}

// ---- shaders ----

const char* kUniformVs = R"(#version 330 core
uniform mat4 u_world;
uniform mat4 u_view;
uniform mat4 u_proj;
layout(location = 0) in vec3 a_pos;
void main() { gl_Position = u_proj * u_view * u_world * vec4(a_pos, 1.0); }
)";
const char* kColourFs = R"(#version 330 core
uniform vec4 u_colour;
out vec4 o_colour;
void main() { o_colour = u_colour; }
)";
const char* kTexturedFs = R"(#version 330 core
uniform sampler2D u_tex;
out vec4 o_colour;
void main() { o_colour = texture(u_tex, vec2(0.5)); }
)";
const char* kInstancedVs = R"(#version 330 core
uniform mat4 u_view;
uniform mat4 u_proj;
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 i_offset;
layout(location = 2) in vec4 i_colour;
out vec4 v_colour;
void main() { v_colour = i_colour; gl_Position = u_proj * u_view * vec4(a_pos + i_offset, 1.0); }
)";
const char* kVaryingFs = R"(#version 330 core
in vec4 v_colour;
out vec4 o_colour;
void main() { o_colour = v_colour; }
)";
const char* kBlockVs = R"(#version 330 core
layout(std140) uniform Camera { mat4 s_view; mat4 s_proj; };
uniform samplerBuffer u_objects;
uniform int u_object;
layout(location = 0) in vec3 a_pos;
out vec4 v_colour;
void main() {
  int b = u_object * 5;
  mat4 w = mat4(texelFetch(u_objects, b), texelFetch(u_objects, b + 1), texelFetch(u_objects, b + 2),
                texelFetch(u_objects, b + 3));
  v_colour = texelFetch(u_objects, b + 4);
  gl_Position = s_proj * s_view * w * vec4(a_pos, 1.0);
}
)";

GLuint compileShader(GLenum type, const char* src) {
  const GLuint s = GLV(glCreateShader(type));
  GL(glShaderSource(s, 1, &src, nullptr));
  GL(glCompileShader(s));
  GLint ok = 0;
  GL(glGetShaderiv(s, GL_COMPILE_STATUS, &ok));
  if (!ok) {
    char log[2048] = {0};
    GL(glGetShaderInfoLog(s, sizeof(log), nullptr, log));
    die(std::string("shader did not compile: ") + log);
  }
  return s;
}

/// Attaches and links the two shaders into `p`.
void linkFromSource(GLuint p, const char* vs, const char* fs) {
  const GLuint v = compileShader(GL_VERTEX_SHADER, vs), f = compileShader(GL_FRAGMENT_SHADER, fs);
  GL(glAttachShader(p, v));
  GL(glAttachShader(p, f));
  GL(glLinkProgram(p));
  GLint ok = 0;
  GL(glGetProgramiv(p, GL_LINK_STATUS, &ok));
  if (!ok) die("link failed");
  GL(glDetachShader(p, v));
  GL(glDetachShader(p, f));
  GL(glDeleteShader(v));
  GL(glDeleteShader(f));
}
GLuint program(const char* vs, const char* fs) {
  const GLuint p = GLV(glCreateProgram());
  linkFromSource(p, vs, fs);
  return p;
}

void setMatrix(GLuint p, const char* name, const Eigen::Matrix4f& m) {
  GL(glUniformMatrix4fv(GLV(glGetUniformLocation(p, name)), 1, GL_FALSE, m.data()));
}
void setColour(GLuint p, int k) { GL(glUniform4fv(GLV(glGetUniformLocation(p, "u_colour")), 1, ss::colour(k).data())); }

// ---- what every scenario shares ----

/// The unit quad (-1..1 at z = 0) in a vertex array of the current context, optionally scaled.
struct Quad {
  GLuint vao = 0, vbo = 0, ibo = 0;
};
Quad makeQuad(float scale = 1.0f) {
  Quad q;
  const float v[12] = {-scale, -scale, 0, scale, -scale, 0, scale, scale, 0, -scale, scale, 0};
  const uint16_t i[6] = {0, 1, 2, 0, 2, 3};
  GL(glGenVertexArrays(1, &q.vao));
  GL(glBindVertexArray(q.vao));
  GL(glGenBuffers(1, &q.vbo));
  GL(glBindBuffer(GL_ARRAY_BUFFER, q.vbo));
  GL(glBufferData(GL_ARRAY_BUFFER, sizeof(v), v, GL_STATIC_DRAW));
  GL(glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr));
  GL(glEnableVertexAttribArray(0));
  GL(glGenBuffers(1, &q.ibo));
  GL(glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, q.ibo));
  GL(glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof(i), i, GL_STATIC_DRAW));
  return q;
}

/// Frame f begins: the default framebuffer cleared (frame 1 also causes an error of its own).
void beginFrame(int f) {
  if (f == 1) provokeError();
  GL(glBindFramebuffer(GL_FRAMEBUFFER, 0));
  GL(glViewport(0, 0, ss::kSize, ss::kSize));
  GL(glClearColor(0.05f, 0.1f, 0.15f, 1.0f));
  GL(glEnable(GL_DEPTH_TEST));
  GL(glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT));
}

std::vector<uint8_t> readImage() {
  std::vector<uint8_t> pixels(static_cast<size_t>(ss::kSize) * ss::kSize * 4);
  GL(glPixelStorei(GL_PACK_ALIGNMENT, 1));
  GL(glReadPixels(0, 0, ss::kSize, ss::kSize, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data()));
  return pixels;
}
void writeImage(const std::string& out, const std::vector<uint8_t>& pixels) {
  if (out.empty()) return;
  std::ofstream file(out, std::ios::binary);
  file.write(reinterpret_cast<const char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  if (!file) die("cannot write " + out);
}

/// Frame f ends: the program's error checked (frame 1), the last frame read back, the swap.
void endFrame(const Surface& s, int f, int frames, const std::string& out) {
  if (f == 1) expectProvokedError();
  if (f == frames - 1) writeImage(out, readImage());
  if (!eglSwapBuffers(g_display, s.surface) && !(g_draw_through_exit && g_exiting)) die("eglSwapBuffers failed");
  check("eglSwapBuffers", __LINE__);
}

/// Object k drawn with a program of uniforms u_world, u_view, u_proj (and u_colour if it has one).
void drawObject(GLuint p, int k, int f, float shift = 0.0f) {
  setMatrix(p, "u_world", ss::world(k, shift));
  setMatrix(p, "u_view", ss::view(f));
  setMatrix(p, "u_proj", ss::projection());
  if (GLV(glGetUniformLocation(p, "u_colour")) >= 0) setColour(p, k);
  GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
}

// ---- scenarios ----

void mdi(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kInstancedVs, kVaryingFs);
  makeQuad(ss::kHalf);  // stays bound: the instance attributes go into its vertex array
  struct Instance {
    float offset[3], colour[4];
  };
  std::vector<Instance> instances(8);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector2f c = ss::cellCentre(k);
    instances[k] = Instance{{c.x(), c.y(), 0.0f}, {0, 0, 0, 0}};
    std::memcpy(instances[k].colour, ss::colour(k).data(), 16);
  }
  GLuint ib = 0, indirect = 0;
  GL(glGenBuffers(1, &ib));
  GL(glBindBuffer(GL_ARRAY_BUFFER, ib));
  GL(glBufferData(GL_ARRAY_BUFFER, instances.size() * sizeof(Instance), instances.data(), GL_STATIC_DRAW));
  GL(glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Instance), nullptr));
  GL(glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Instance), reinterpret_cast<void*>(12)));
  for (GLuint a : {1u, 2u}) {
    GL(glEnableVertexAttribArray(a));
    GL(glVertexAttribDivisor(a, 1));
  }
  // {count, instances, first index, base vertex, base instance}: objects 0-3, then 4-5.
  const GLuint commands[10] = {6, 4, 0, 0, 0, 6, 2, 0, 0, 4};
  GL(glGenBuffers(1, &indirect));
  GL(glBindBuffer(GL_DRAW_INDIRECT_BUFFER, indirect));
  GL(glBufferData(GL_DRAW_INDIRECT_BUFFER, sizeof(commands), commands, GL_STATIC_DRAW));
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    setMatrix(p, "u_view", ss::view(f));
    setMatrix(p, "u_proj", ss::projection());
    GL(glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_SHORT, nullptr, 2, 0));
    GL(glDrawElementsInstancedBaseInstance(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr, 2, 6));  // objects 6-7
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

void persistent(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kColourFs);
  constexpr int kRegions = 3, kVertices = 4 * 6;  // 4 objects of two triangles
  constexpr size_t kRegionBytes = kVertices * 3 * sizeof(float);
  const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  GLuint vao = 0, vbo = 0;
  GL(glGenVertexArrays(1, &vao));
  GL(glBindVertexArray(vao));
  GL(glGenBuffers(1, &vbo));
  GL(glBindBuffer(GL_ARRAY_BUFFER, vbo));
  GL(glBufferStorage(GL_ARRAY_BUFFER, kRegions * kRegionBytes, nullptr, flags));
  auto* mapped = static_cast<float*>(GLV(glMapBufferRange(GL_ARRAY_BUFFER, 0, kRegions * kRegionBytes, flags)));
  if (!mapped) die("no persistent mapping");
  GL(glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr));
  GL(glEnableVertexAttribArray(0));
  GLsync fences[kRegions] = {nullptr, nullptr, nullptr};
  for (int f = 0; f < frames; ++f) {
    const int r = f % kRegions;
    if (fences[r]) {  // the GPU is done with what this region held three frames ago
      GLenum w;
      while ((w = GLV(glClientWaitSync(fences[r], GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull))) == GL_TIMEOUT_EXPIRED) {
      }
      if (w == GL_WAIT_FAILED) die("glClientWaitSync failed");
      GL(glDeleteSync(fences[r]));
    }
    float* v = mapped + r * kVertices * 3;
    const float corners[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2f c = ss::cellCentre(k, ss::frameShift(f));
      for (int i = 0; i < 6; ++i, v += 3) {
        v[0] = c.x() + ss::kHalf * corners[i][0];
        v[1] = c.y() + ss::kHalf * corners[i][1];
        v[2] = 0.0f;
      }
    }
    beginFrame(f);
    GL(glUseProgram(p));
    setMatrix(p, "u_world", Eigen::Matrix4f::Identity());
    setMatrix(p, "u_view", ss::view(f));
    setMatrix(p, "u_proj", ss::projection());
    for (int k = 0; k < 4; ++k) {
      setColour(p, k);
      GL(glDrawArrays(GL_TRIANGLES, r * kVertices + 6 * k, 6));
    }
    fences[r] = GLV(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
    endFrame(s, f, frames, out);
  }
  for (GLsync fence : fences)
    if (fence) GL(glDeleteSync(fence));
  GL(glUnmapBuffer(GL_ARRAY_BUFFER));
  destroy(s);
}

void uboTbo(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kBlockVs, kVaryingFs);
  GL(glUniformBlockBinding(p, GLV(glGetUniformBlockIndex(p, "Camera")), 2));
  const Quad q = makeQuad();
  GLuint ubo = 0, tbo = 0, tex = 0;
  GL(glGenBuffers(1, &ubo));
  GL(glBindBuffer(GL_UNIFORM_BUFFER, ubo));
  GL(glBufferData(GL_UNIFORM_BUFFER, 128, nullptr, GL_DYNAMIC_DRAW));
  GL(glGenBuffers(1, &tbo));
  GL(glBindBuffer(GL_TEXTURE_BUFFER, tbo));
  GL(glBufferData(GL_TEXTURE_BUFFER, 4 * 5 * 16, nullptr, GL_DYNAMIC_DRAW));
  GL(glGenTextures(1, &tex));
  GL(glActiveTexture(GL_TEXTURE3));
  GL(glBindTexture(GL_TEXTURE_BUFFER, tex));
  GL(glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, tbo));
  GL(glUseProgram(p));
  GL(glUniform1i(GLV(glGetUniformLocation(p, "u_objects")), 3));
  for (int f = 0; f < frames; ++f) {
    const Eigen::Matrix4f view = ss::view(f), proj = ss::projection();
    GL(glBindBuffer(GL_UNIFORM_BUFFER, ubo));
    GL(glBufferSubData(GL_UNIFORM_BUFFER, 0, 64, view.data()));
    GL(glBufferSubData(GL_UNIFORM_BUFFER, 64, 64, proj.data()));
    GL(glBindBufferBase(GL_UNIFORM_BUFFER, 2, ubo));
    for (int k = 0; k < 4; ++k) {
      GL(glBufferSubData(GL_TEXTURE_BUFFER, k * 80, 64, ss::world(k).data()));
      GL(glBufferSubData(GL_TEXTURE_BUFFER, k * 80 + 64, 16, ss::colour(k).data()));
    }
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      GL(glUniform1i(GLV(glGetUniformLocation(p, "u_object")), k));
      GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

void binary(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  GLint formats = 0;
  GL(glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats));
  const GLuint from_source = program(kUniformVs, kColourFs);
  GLint length = 0;
  GL(glGetProgramiv(from_source, GL_PROGRAM_BINARY_LENGTH, &length));
  std::vector<uint8_t> bytes(static_cast<size_t>(std::max(length, 1)));
  GLenum format = 0;
  GLsizei written = 0;
  GL(glGetProgramBinary(from_source, length, &written, &format, bytes.data()));
  GL(glDeleteProgram(from_source));
  // As a shader cache does: the stored binary first; where it is refused, the source.
  const GLuint p = GLV(glCreateProgram());
  GLint linked = 0;
  if (written > 0) {
    GL(glProgramBinary(p, format, bytes.data(), written));
    GL(glGetProgramiv(p, GL_LINK_STATUS, &linked));
  }
  std::printf("binary_formats=%d binary_bytes=%d binary_loaded=%d\n", formats, written, linked);
  if (!linked) linkFromSource(p, kUniformVs, kColourFs);
  const Quad q = makeQuad();
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

/// The uploads the loader thread made for one frame: its vertices (4 quads) and their fence.
struct Upload {
  GLuint vbo = 0;
  GLsync fence = nullptr;
};

/// A channel of uploads from the loader thread to the main thread.
struct Uploads {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<Upload> ready;
  bool stop = false;
  void push(const Upload& u) {
    std::lock_guard<std::mutex> lock(mutex);
    ready.push_back(u);
    changed.notify_all();
  }
  Upload pop() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return !ready.empty(); });
    const Upload u = ready.front();
    ready.pop_front();
    changed.notify_all();
    return u;
  }
  /// The loader waits while two uploads are ahead of the main thread.
  bool waitForRoom() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return ready.size() < 2 || stop; });
    return !stop;
  }
};

/// The loader thread: a shared context of its own (its own small pbuffer), each frame's vertices
/// in a new buffer, the objects' textures updated, and a draw into a framebuffer object of its own.
void loader(EGLContext share, GLuint* textures, int frames, Uploads* uploads) {
  Surface s = makeSurface(16, share);
  makeCurrent(s);
  GLuint fbo = 0, target = 0;
  GL(glGenTextures(1, &target));
  GL(glBindTexture(GL_TEXTURE_2D, target));
  GL(glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 16, 16));
  GL(glGenFramebuffers(1, &fbo));
  GL(glBindFramebuffer(GL_FRAMEBUFFER, fbo));
  GL(glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0));
  if (GLV(glCheckFramebufferStatus(GL_FRAMEBUFFER)) != GL_FRAMEBUFFER_COMPLETE) die("loader framebuffer incomplete");
  const GLuint p = program(kUniformVs, kColourFs);
  const Quad q = makeQuad();
  for (int f = 0; f < frames && uploads->waitForRoom(); ++f) {
    std::vector<float> v;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2f c = ss::cellCentre(k, ss::frameShift(f));
      static const float kCorners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& corner : kCorners)
        v.insert(v.end(), {c.x() + ss::kHalf * corner[0], c.y() + ss::kHalf * corner[1], 0.0f});
    }
    Upload u;
    GL(glGenBuffers(1, &u.vbo));
    GL(glBindBuffer(GL_ARRAY_BUFFER, u.vbo));
    GL(glBufferData(GL_ARRAY_BUFFER, v.size() * sizeof(float), v.data(), GL_STATIC_DRAW));
    for (int k = 0; k < 4; ++k) {
      std::vector<uint8_t> texels(4 * 4 * 4);
      for (size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<uint8_t>(ss::colour(k)[i % 4] * 255.0f + 0.5f);
      GL(glBindTexture(GL_TEXTURE_2D, textures[k]));
      GL(glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, 4, GL_RGBA, GL_UNSIGNED_BYTE, texels.data()));
    }
    // Something drawn on this thread too (an impostor, a generated texture) while the main thread draws.
    GL(glBindFramebuffer(GL_FRAMEBUFFER, fbo));
    GL(glViewport(0, 0, 16, 16));
    GL(glClear(GL_COLOR_BUFFER_BIT));
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    drawObject(p, f % 4, f);
    u.fence = GLV(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
    GL(glFlush());
    uploads->push(u);
  }
  destroy(s);
}

void threads(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kTexturedFs);
  GLuint textures[4];
  GL(glGenTextures(4, textures));
  for (GLuint t : textures) {
    GL(glBindTexture(GL_TEXTURE_2D, t));
    GL(glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 4, 4, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr));
    GL(glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST));
    GL(glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST));
  }
  GL(glFinish());  // the textures exist before the loader's context uses them
  const Quad q = makeQuad();  // its index buffer; the loader's buffers give the vertices
  Uploads uploads;
  std::thread load(loader, s.context, textures, frames, &uploads);
  // A third context, not shared, used mid-frame (a tool window, a second view).
  Surface other = makeSurface(32);
  GLuint other_program = 0;
  Quad other_quad;
  GLuint previous_vbo = 0;
  for (int f = 0; f < frames; ++f) {
    const Upload u = uploads.pop();
    GL(glWaitSync(u.fence, 0, GL_TIMEOUT_IGNORED));
    GL(glDeleteSync(u.fence));
    GL(glBindVertexArray(q.vao));
    GL(glBindBuffer(GL_ARRAY_BUFFER, u.vbo));
    GL(glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr));
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glActiveTexture(GL_TEXTURE0));
    for (int k = 0; k < 4; ++k) {
      if (k == 2) {  // mid-frame: a draw in the other context, then back
        makeCurrent(other);
        if (!other_program) {
          other_program = program(kUniformVs, kColourFs);
          other_quad = makeQuad();
        }
        GL(glViewport(0, 0, 32, 32));
        GL(glClearColor(1, 1, 1, 1));
        GL(glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT));
        GL(glUseProgram(other_program));
        GL(glBindVertexArray(other_quad.vao));
        drawObject(other_program, 5, f);
        uint8_t pixel[4] = {0, 0, 0, 0};
        GL(glReadPixels(16, 16, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel));
        if (pixel[0] != 255) die("the other context's image is wrong");
        makeCurrent(s);
      }
      GL(glBindTexture(GL_TEXTURE_2D, textures[k]));
      // Vertices of object k are 4 .. 4k + 3 of the upload: base vertex, world = identity.
      setMatrix(p, "u_world", Eigen::Matrix4f::Identity());
      setMatrix(p, "u_view", ss::view(f));
      setMatrix(p, "u_proj", ss::projection());
      GL(glDrawElementsBaseVertex(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr, 4 * k));
    }
    endFrame(s, f, frames, out);
    if (previous_vbo) GL(glDeleteBuffers(1, &previous_vbo));
    previous_vbo = u.vbo;
  }
  {
    std::lock_guard<std::mutex> lock(uploads.mutex);
    uploads.stop = true;
    uploads.changed.notify_all();
  }
  load.join();
  for (const Upload& u : uploads.ready) {
    GL(glDeleteSync(u.fence));
    GL(glDeleteBuffers(1, &u.vbo));
  }
  makeCurrent(other);
  destroy(other);
  makeCurrent(s);
  destroy(s);
}

void destroyMidFrame(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  GLuint p = program(kUniformVs, kColourFs);
  Quad q = makeQuad();
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      if (f == 2 && k == 2) {  // the context is lost: everything made again, the frame drawn again
        destroy(s);
        s = makeSurface(ss::kSize);
        makeCurrent(s);
        p = program(kUniformVs, kColourFs);
        q = makeQuad();
        std::printf("context made again in frame %d\n", f);
        beginFrame(f);
        GL(glUseProgram(p));
        GL(glBindVertexArray(q.vao));
        for (int j = 0; j < k; ++j) drawObject(p, j, f);
      }
      drawObject(p, k, f);
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

/// Another thread calls exit() while the main thread is in the middle of a frame (its context
/// current, two of its four draws made, after `frames` frames swapped), where the main thread
/// stays; with --draw-through-exit 1 it draws on meanwhile (checking nothing: the driver is torn
/// down under it, and a swap may fail).
void exitThread(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kColourFs);
  const Quad q = makeQuad();
  static std::atomic<bool> written{false}, parked{false};
  std::thread exiter([] {
    while (!written.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_exiting = true;
    while (!parked.load() && !g_draw_through_exit) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::printf("exit() from another thread\n");
    std::fflush(stdout);
    std::exit(0);
  });
  exiter.detach();
  for (int f = 0;; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      if (f == frames && k == 2 && !g_draw_through_exit) {
        parked = true;
        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      drawObject(p, k, f);
    }
    endFrame(s, f, frames, out);
    if (f == frames - 1) {
      written = true;
      while (!g_exiting) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario, out;
  int frames = ss::kFrames;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--scenario") scenario = v;
    else if (a == "--out") out = v;
    else if (a == "--frames") frames = std::atoi(v.c_str());
    else if (a == "--draw-through-exit") g_draw_through_exit = v == "1";
    else die("unknown option " + a);
  }
  if (frames < 3) die("--frames must be at least 3");
  const std::vector<std::pair<std::string, std::function<void(int, const std::string&)>>> scenarios = {
      {"mdi", mdi},         {"persistent", persistent},     {"ubo_tbo", uboTbo},          {"binary", binary},
      {"threads", threads}, {"destroy", destroyMidFrame}, {"exit_thread", exitThread}};
  bool found = false;
  for (const auto& s : scenarios) {
    if (scenario != "all" && scenario != s.first) continue;
    found = true;
    std::printf("scenario %s\n", s.first.c_str());
    std::fflush(stdout);
    s.second(frames, out);
  }
  if (!found) die("unknown scenario '" + scenario + "'");
  std::fflush(stdout);
  return 0;
}
