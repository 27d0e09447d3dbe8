// OpenGL 4.5 core test program that draws the way real engines do (engine_scene.h), for the
// capture tests: one instanced draw placed by attributes in a persistent, coherent mapping
// (glBufferStorage); view and projection in a std140 uniform block filled with glBufferSubData
// into one of three rotating buffers; a fragment shader with a second output at location 1; a 2D
// overlay quad (HUD) drawn last; a glProgramBinary attempt before linking from source.
//   gl_engine_program [--size WxH] [--frames N] [--out FILE] [--offscreen 0|1] [--indirect 0|1]
// --out writes the program's own read-back of its last frame (RGBA, bottom row first).
// --offscreen 1 draws the scene into a G-buffer of its own (color at draw buffer 0, normals at 1,
// depth texture) and composites color and normals into the default framebuffer, so that a capture
// that wrote over draw buffer 1 would change the output. --indirect 1 draws the same instances
// with glMultiDrawElementsIndirect: two commands (instances 0-1, then instance 2) from a draw
// indirect buffer. Prints binary_formats=N (what GL_NUM_PROGRAM_BINARY_FORMATS said).
#include "engine_scene.h"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include "egl_pbuffer.h"
#include "fullscreen_triangle.h"
#include "gl_common/sanitizer_options.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace es = viper::engine_scene;

namespace {

[[noreturn]] void die(const std::string& what) { viper::test_program::die("gl_engine_program", what); }
GLuint compile(GLenum type, const char* src) { return viper::test_program::compile("gl_engine_program", type, src); }

// As engines with a shader cache do: try a stored binary first, link from source if refused.
GLuint program(const char* vs, const char* fs) {
  GLuint p = glCreateProgram();
  const char stale[16] = "not a binary";
  glProgramBinary(p, 0x8fff, stale, sizeof(stale));
  while (glGetError() != GL_NO_ERROR) {
  }
  GLint linked = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &linked);
  if (linked) return p;
  glAttachShader(p, compile(GL_VERTEX_SHADER, vs));
  glAttachShader(p, compile(GL_FRAGMENT_SHADER, fs));
  glLinkProgram(p);
  glGetProgramiv(p, GL_LINK_STATUS, &linked);
  if (!linked) die("link failed");
  return p;
}

const char* kSceneVs = R"(#version 330 core
layout(std140) uniform Matrices { mat4 u_view_matrix; mat4 u_projection_matrix; };
layout(location = 0) in vec3 i_position;
layout(location = 8) in vec3 i_origin;
layout(location = 9) in vec4 i_rotation;
layout(location = 10) in vec4 i_scale;
out vec3 normal;
vec3 rotateVector(vec4 quat, vec3 vec) { return vec + 2.0 * cross(cross(vec, quat.xyz) + quat.w * vec, quat.xyz); }
void main() {
  vec3 p = rotateVector(i_rotation, i_position * i_scale.xyz) + i_origin;
  normal = rotateVector(i_rotation, vec3(0.0, 0.0, 1.0));
  gl_Position = u_projection_matrix * u_view_matrix * vec4(p, 1.0);
}
)";
const char* kSceneFs = R"(#version 330 core
in vec3 normal;
uniform vec4 u_color;
layout(location = 0) out vec4 o_diffuse_color;
layout(location = 1) out vec4 o_normal_color;
void main() { o_diffuse_color = u_color; o_normal_color = vec4(0.5 * normalize(normal) + 0.5, 1.0); }
)";
const char* kOverlayVs = R"(#version 330 core
uniform vec2 center;
uniform vec2 size;
layout(location = 0) in vec2 Position;
void main() { gl_Position = vec4(Position * size + center, 0.0, 1.0); }
)";
const char* kOverlayFs = R"(#version 330 core
out vec4 color;
void main() { color = vec4(1.0, 0.9, 0.1, 1.0); }
)";
const char* kCompositeFs = R"(#version 330 core
uniform sampler2D u_color;
uniform sampler2D u_normal;
in vec2 uv;
out vec4 color;
void main() { color = vec4(0.5 * texture(u_color, uv).rgb + 0.5 * texture(u_normal, uv).rgb, 1.0); }
)";

uint16_t half(float f) {  // exact for the scene's scales (few mantissa bits, normal range)
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  const uint32_t sign = (bits >> 16) & 0x8000u, exponent = ((bits >> 23) & 0xffu) - 127 + 15,
                 mantissa = (bits >> 13) & 0x3ffu;
  return static_cast<uint16_t>(sign | (exponent << 10) | mantissa);
}

GLuint texture2d(GLenum internal, GLenum format, GLenum type, int w, int h) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  int offscreen = 0, indirect = 0;
  const viper::test_program::Options options = viper::test_program::parseOptions(
      "gl_engine_program", argc, argv, true, [&](const std::string& a, const std::string& v) {
        if (a == "--offscreen") offscreen = std::atoi(v.c_str());
        else if (a == "--indirect") indirect = std::atoi(v.c_str());
        else return false;
        return true;
      });
  const int width = options.width, height = options.height, frames = options.frames;
  const std::string& out = options.out;

  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  const viper::test_program::EglPbuffer pbuffer =
      viper::test_program::makeCurrentPbuffer("gl_engine_program", width, height, ctx_attrs, "GL 4.5 context");
  EGLDisplay dpy = pbuffer.display;
  EGLSurface surface = pbuffer.surface;

  GLint binary_formats = -1;
  glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &binary_formats);
  const GLuint scene = program(kSceneVs, kSceneFs);
  const GLuint overlay = program(kOverlayVs, kOverlayFs);
  glUniformBlockBinding(scene, glGetUniformBlockIndex(scene, "Matrices"), 0);

  // The quad mesh, and its instances' records (44 bytes: origin, quaternion, 4 half-float scales,
  // 8 bytes the shader does not read) in a persistently mapped buffer.
  GLuint vao = 0, vbo = 0, ibo = 0, instances = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  const float quad[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof(quad), quad, GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, &ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof(indices), indices, GL_STATIC_DRAW);
  constexpr int kStride = 44;
  const GLbitfield map_flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  glGenBuffers(1, &instances);
  glBindBuffer(GL_ARRAY_BUFFER, instances);
  glBufferStorage(GL_ARRAY_BUFFER, es::kInstances * kStride, nullptr, map_flags);
  auto* records = static_cast<uint8_t*>(glMapBufferRange(GL_ARRAY_BUFFER, 0, es::kInstances * kStride, map_flags));
  if (!records) die("no persistent mapping");
  glVertexAttribPointer(8, 3, GL_FLOAT, GL_FALSE, kStride, nullptr);
  glVertexAttribPointer(9, 4, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<void*>(12));
  glVertexAttribPointer(10, 4, GL_HALF_FLOAT, GL_FALSE, kStride, reinterpret_cast<void*>(28));
  for (GLuint a : {8u, 9u, 10u}) {
    glEnableVertexAttribArray(a);
    glVertexAttribDivisor(a, 1);
  }
  // {count, instances, first index, base vertex, base instance} x 2, used by --indirect.
  const GLuint commands[10] = {6, 2, 0, 0, 0, 6, 1, 0, 0, 2};
  GLuint indirect_buffer = 0;
  glGenBuffers(1, &indirect_buffer);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, indirect_buffer);
  glBufferData(GL_DRAW_INDIRECT_BUFFER, sizeof(commands), commands, GL_STATIC_DRAW);
  GLuint overlay_vao = 0, overlay_vbo = 0;
  glGenVertexArrays(1, &overlay_vao);
  glBindVertexArray(overlay_vao);
  const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
  glGenBuffers(1, &overlay_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, overlay_vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof(corners), corners, GL_STATIC_DRAW);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);

  // View and projection: three uniform buffers used in turn, filled with glBufferSubData.
  GLuint ubos[3];
  glGenBuffers(3, ubos);
  for (GLuint u : ubos) {
    glBindBuffer(GL_UNIFORM_BUFFER, u);
    glBufferData(GL_UNIFORM_BUFFER, 128, nullptr, GL_DYNAMIC_DRAW);
  }

  GLuint gbuffer = 0, composite = 0, composite_vao = 0;
  if (offscreen) {
    glGenFramebuffers(1, &gbuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, gbuffer);
    glActiveTexture(GL_TEXTURE0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                           texture2d(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, width, height), 0);
    glActiveTexture(GL_TEXTURE1);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D,
                           texture2d(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, width, height), 0);
    glActiveTexture(GL_TEXTURE2);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D,
                           texture2d(GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_FLOAT, width, height), 0);
    glActiveTexture(GL_TEXTURE0);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, bufs);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("G-buffer incomplete");
    composite = program(viper::test_program::kFullScreenTriangleVs, kCompositeFs);
    glUseProgram(composite);
    glUniform1i(glGetUniformLocation(composite, "u_color"), 0);
    glUniform1i(glGetUniformLocation(composite, "u_normal"), 1);
    glGenVertexArrays(1, &composite_vao);
  }

  std::vector<uint8_t> pixels(static_cast<size_t>(width) * height * 4);
  for (int f = 0; f < frames; ++f) {
    const GLuint ubo = ubos[f % 3];
    const Eigen::Matrix4f view = es::view(f), proj = es::projection();
    glBindBuffer(GL_UNIFORM_BUFFER, ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, 64, view.data());
    glBufferSubData(GL_UNIFORM_BUFFER, 64, 64, proj.data());
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, ubo);
    for (int k = 0; k < es::kInstances; ++k) {
      uint8_t* r = records + k * kStride;
      const Eigen::Vector3f o = es::origin(k, f), s = es::scale(k);
      const Eigen::Quaternionf q = es::rotation(k, f);
      const float quat[4] = {q.x(), q.y(), q.z(), q.w()};
      const uint16_t halves[4] = {half(s.x()), half(s.y()), half(s.z()), half(1.0f)};
      std::memcpy(r, o.data(), 12);
      std::memcpy(r + 12, quat, 16);
      std::memcpy(r + 28, halves, 8);
    }

    glBindFramebuffer(GL_FRAMEBUFFER, gbuffer);
    glViewport(0, 0, width, height);
    glClearColor(0.1f, 0.1f, 0.2f, 1.0f);
    glEnable(GL_DEPTH_TEST);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(scene);
    glUniform4f(glGetUniformLocation(scene, "u_color"), 0.8f, 0.3f, 0.2f, 1.0f);
    glBindVertexArray(vao);
    if (indirect)
      glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_SHORT, nullptr, 2, 0);
    else
      glDrawElementsInstanced(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr, es::kInstances);

    glDisable(GL_DEPTH_TEST);
    if (offscreen) {
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      glUseProgram(composite);
      glBindVertexArray(composite_vao);
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glUseProgram(overlay);
    glUniform2f(glGetUniformLocation(overlay, "center"), es::kOverlayX, es::kOverlayY);
    glUniform2f(glGetUniformLocation(overlay, "size"), es::kOverlayHalf, es::kOverlayHalf);
    glBindVertexArray(overlay_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);

    if (f == frames - 1 && !out.empty()) {
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    }
    eglSwapBuffers(dpy, surface);
    glFinish();  // the next frame writes the mapped records again
  }
  if (glGetError() != GL_NO_ERROR) die("GL error");
  if (!out.empty()) {
    std::ofstream file(out, std::ios::binary);
    file.write(reinterpret_cast<const char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  }
  std::printf("binary_formats=%d\n", binary_formats);
  return 0;
}
