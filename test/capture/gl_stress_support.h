// What the scenarios of the stress program (gl_stress_program.cpp) share: glGetError after every
// GL call (GL, GLV), the program's own deliberate error, EGL pbuffers and contexts (Mesa's
// surfaceless platform, else the first EGL device), its shaders, the quad, and the frame's start and
// end. Include in that one program only, after its GL headers.
#pragma once

#include "stress_scene.h"

#include <Eigen/Core>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace viper {
namespace stress_program {

[[noreturn]] inline void die(const std::string& what) {
  std::fprintf(stderr, "gl_stress_program: %s\n", what.c_str());
  std::fflush(stderr);
  std::_Exit(1);
}

// ---- glGetError after every call ----

/// The error the program caused on purpose and has not read yet (checks wait for it).
inline thread_local GLenum t_provoked = GL_NO_ERROR;
/// exit_thread: the other thread is about to call exit().
inline std::atomic<bool> g_exiting{false};
/// --draw-through-exit 1: the main thread draws on while exit() runs (and stops checking).
inline bool g_draw_through_exit = false;

inline void check(const char* what, int line) {
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
inline T checked(T value, const char* what, int line) {
  check(what, line);
  return value;
}
#define GL(call) ((call), ::viper::stress_program::check(#call, __LINE__))
#define GLV(call) ::viper::stress_program::checked((call), #call, __LINE__)

/// An error of the program's own: glEnable of an enum that is none.
inline void provokeError() {
  glEnable(0x1234);
  t_provoked = GL_INVALID_ENUM;
}
/// After the calls that followed: the program's error is what glGetError reports, and only it.
inline void expectProvokedError() {
  const GLenum e = glGetError();
  if (e != t_provoked) die("the program's own GL error changed: expected 0x500, read 0x" + std::to_string(e));
  t_provoked = GL_NO_ERROR;
  check("reading the program's own error", __LINE__);
}

// ---- EGL ----

inline EGLDisplay g_display = EGL_NO_DISPLAY;
inline EGLConfig g_config = nullptr;

/// Initialised, with an RGBA8 + depth 24 pbuffer config for desktop OpenGL in g_config.
inline bool tryDisplay(EGLDisplay display) {
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr)) return false;
  const EGLint attrs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_RED_SIZE, 8,
                          EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24, EGL_NONE};
  EGLint n = 0;
  if (!eglChooseConfig(display, attrs, &g_config, 1, &n) || n == 0) return false;
  g_display = display;
  return true;
}

/// Mesa's surfaceless platform, else (a GPU driver without Mesa's platforms) the first EGL device.
inline void initDisplay() {
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

/// A pbuffer and a GL 4.5 core context, or (`compatibility`) the driver's compatibility profile
/// (legacy formats and extension names, as older engines use them).
inline Surface makeSurface(int size, EGLContext share = EGL_NO_CONTEXT, bool compatibility = false) {
  initDisplay();
  eglBindAPI(EGL_OPENGL_API);
  const EGLint surface_attrs[] = {EGL_WIDTH, size, EGL_HEIGHT, size, EGL_NONE};
  const EGLint core_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  const EGLint compatibility_attrs[] = {EGL_NONE};
  Surface s;
  s.surface = eglCreatePbufferSurface(g_display, g_config, surface_attrs);
  s.context = eglCreateContext(g_display, g_config, share, compatibility ? compatibility_attrs : core_attrs);
  if (s.surface == EGL_NO_SURFACE || s.context == EGL_NO_CONTEXT) die("no EGL pbuffer or GL context");
  return s;
}
inline void makeCurrent(const Surface& s) {
  if (!eglMakeCurrent(g_display, s.surface, s.surface, s.context)) die("eglMakeCurrent failed");
  static bool said = false;
  if (!said) {
    said = true;
    std::printf("renderer %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  }
}
inline void destroy(Surface& s) {
  if (!eglMakeCurrent(g_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT)) die("eglMakeCurrent(none) failed");
  eglDestroyContext(g_display, s.context);
  eglDestroySurface(g_display, s.surface);
  s = Surface();
}

// ---- shaders ----

inline const char* const kUniformVs = R"(#version 330 core
uniform mat4 u_world;
uniform mat4 u_view;
uniform mat4 u_proj;
layout(location = 0) in vec3 a_pos;
void main() { gl_Position = u_proj * u_view * u_world * vec4(a_pos, 1.0); }
)";
inline const char* const kColourFs = R"(#version 330 core
uniform vec4 u_colour;
out vec4 o_colour;
void main() { o_colour = u_colour; }
)";
// blend_depth: the quad's own x (-1..1) to the fragment, which is mostly transparent left of -0.4.
inline const char* const kLocalXVs = R"(#version 330 core
uniform mat4 u_world;
uniform mat4 u_view;
uniform mat4 u_proj;
layout(location = 0) in vec3 a_pos;
out float v_x;
void main() { v_x = a_pos.x; gl_Position = u_proj * u_view * u_world * vec4(a_pos, 1.0); }
)";
inline const char* const kVeiledFs = R"(#version 330 core
uniform vec4 u_colour;
in float v_x;
out vec4 o_colour;
void main() { o_colour = vec4(u_colour.rgb, v_x < -0.4 ? 0.3 : 1.0); }
)";
inline const char* const kTexturedFs = R"(#version 330 core
uniform sampler2D u_tex;
out vec4 o_colour;
void main() { o_colour = texture(u_tex, vec2(0.5)); }
)";
inline const char* const kInstancedVs = R"(#version 330 core
uniform mat4 u_view;
uniform mat4 u_proj;
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 i_offset;
layout(location = 2) in vec4 i_colour;
out vec4 v_colour;
void main() { v_colour = i_colour; gl_Position = u_proj * u_view * vec4(a_pos + i_offset, 1.0); }
)";
inline const char* const kVaryingFs = R"(#version 330 core
in vec4 v_colour;
out vec4 o_colour;
void main() { o_colour = v_colour; }
)";
inline const char* const kBlockVs = R"(#version 330 core
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

inline GLuint compileShader(GLenum type, const char* src) {
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
inline void linkFromSource(GLuint p, const char* vs, const char* fs) {
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
inline GLuint program(const char* vs, const char* fs) {
  const GLuint p = GLV(glCreateProgram());
  linkFromSource(p, vs, fs);
  return p;
}

inline void setMatrix(GLuint p, const char* name, const Eigen::Matrix4f& m) {
  GL(glUniformMatrix4fv(GLV(glGetUniformLocation(p, name)), 1, GL_FALSE, m.data()));
}
inline void setColour(GLuint p, int k) { GL(glUniform4fv(GLV(glGetUniformLocation(p, "u_colour")), 1, stress_scene::colour(k).data())); }

// ---- what every scenario shares ----

/// The unit quad (-1..1 at z = 0) in a vertex array of the current context, optionally scaled.
struct Quad {
  GLuint vao = 0, vbo = 0, ibo = 0;
};
inline Quad makeQuad(float scale = 1.0f) {
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
inline void beginFrame(int f) {
  if (f == 1) provokeError();
  GL(glBindFramebuffer(GL_FRAMEBUFFER, 0));
  GL(glViewport(0, 0, stress_scene::kSize, stress_scene::kSize));
  GL(glClearColor(0.05f, 0.1f, 0.15f, 1.0f));
  GL(glEnable(GL_DEPTH_TEST));
  GL(glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT));
}

inline std::vector<uint8_t> readImage() {
  std::vector<uint8_t> pixels(static_cast<size_t>(stress_scene::kSize) * stress_scene::kSize * 4);
  GL(glPixelStorei(GL_PACK_ALIGNMENT, 1));
  GL(glReadPixels(0, 0, stress_scene::kSize, stress_scene::kSize, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data()));
  return pixels;
}
inline void writeImage(const std::string& out, const std::vector<uint8_t>& pixels) {
  if (out.empty()) return;
  std::ofstream file(out, std::ios::binary);
  file.write(reinterpret_cast<const char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  if (!file) die("cannot write " + out);
}

/// Frame f ends: the program's error checked (frame 1), the last frame read back, the swap.
inline void endFrame(const Surface& s, int f, int frames, const std::string& out) {
  if (f == 1) expectProvokedError();
  if (f == frames - 1) writeImage(out, readImage());
  if (!eglSwapBuffers(g_display, s.surface) && !(g_draw_through_exit && g_exiting)) die("eglSwapBuffers failed");
  check("eglSwapBuffers", __LINE__);
}

/// Object k drawn with a program of uniforms u_world, u_view, u_proj (and u_colour if it has one).
inline void drawObject(GLuint p, int k, int f, float shift = 0.0f) {
  setMatrix(p, "u_world", stress_scene::world(k, shift));
  setMatrix(p, "u_view", stress_scene::view(f));
  setMatrix(p, "u_proj", stress_scene::projection());
  if (GLV(glGetUniformLocation(p, "u_colour")) >= 0) setColour(p, k);
  GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
}

// Scenarios in gl_stress_compat.cpp: matrices passed otherwise, the compatibility profile.
void combinedMatrices(int frames, const std::string& out);
void fixedFunction(int frames, const std::string& out);
void windowQueries(int frames, const std::string& out);
void extensionNames(int frames, const std::string& out);

}  // namespace stress_program
}  // namespace viper
