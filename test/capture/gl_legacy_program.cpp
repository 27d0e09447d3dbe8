// OpenGL 3.0 compatibility-context test program that draws the way Minetest's Irrlicht driver does,
// for the capture tests: GLSL 1.20 shaders that read the fixed-function state
// (gl_ModelViewProjectionMatrix, gl_Vertex) and write gl_FragColor; before each draw the view is
// loaded into GL_MODELVIEW and the world multiplied onto it; vertices from conventional vertex
// arrays. The three quads of engine_scene.h, each a different way:
//   quad 0: glLoadMatrixf(view), glMultMatrixf(world); vertices and indices in client memory;
//   quad 1: the same matrices; vertices and indices in buffers filled with glBufferDataARB
//           (looked up with eglGetProcAddress, as Irrlicht does);
//   quad 2: glLoadMatrixf(view), glPushMatrix, glTranslatef/glRotatef/glScalef, glPopMatrix;
//           non-indexed glDrawArrays from client memory.
// Then a depth-only clear and a "hand" quad near the camera (with the same program), and a 2D HUD
// quad without any program (fixed function), as Minetest draws its wielded item and HUD.
// Without any program, as Minetest draws its sky and particles: before the world, a "sky" quad (top
// right, far away) and, after the quads, a small "particle" that writes depth in front of quad 0
// (its pixels must have its id, not quad 0's, since their depth is the particle's); both with an
// identity view loaded (their stack view is re-expressed against the frame's).
// And what the layer cannot record, which its capture must report (DrawRecord::gaps): a
// line loop with the same program (below them; no mesh) and a quad whose GLSL 1.30 fragment shader
// declares its own output (top left; not rewritten, so no ids; its profile entry names a world
// matrix the program does not have).
//   gl_legacy_program [--size WxH] [--frames N] [--out FILE]
// --out writes the program's own read-back of its last frame (RGBA, bottom row first).
#include "engine_scene.h"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include "egl_pbuffer.h"
#include "gl_common/sanitizer_options.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace es = viper::engine_scene;

namespace {

[[noreturn]] void die(const std::string& what) { viper::test_program::die("gl_legacy_program", what); }
GLuint compile(GLenum type, const char* src) { return viper::test_program::compile("gl_legacy_program", type, src); }

// Minetest's prelude names the fixed-function state with its own names.
const char* kVs = R"(#version 120
#define mWorldViewProj gl_ModelViewProjectionMatrix
#define inVertexPosition gl_Vertex
void main() { gl_Position = mWorldViewProj * inVertexPosition; }
)";
const char* kFs = R"(#version 120
uniform vec4 u_color;
void main() { gl_FragColor = u_color; }
)";
const char* kRefusedVs = R"(#version 130
#define VIPER_TEST_NOT_REWRITTEN 1
void main() { gl_Position = vec4(gl_Vertex.xy * 0.08 + vec2(-0.85, 0.8), 0.0, 1.0); }
)";
const char* kRefusedFs = R"(#version 130
out vec4 frag;
void main() { frag = vec4(0.2, 0.9, 0.3, 1.0); }
)";

// GL_PROJECTION and GL_MODELVIEW loaded (the model-view only if given), GL_MODELVIEW current after.
void loadMatrices(const Eigen::Matrix4f& projection, const std::optional<Eigen::Matrix4f>& modelview) {
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixf(projection.data());
  glMatrixMode(GL_MODELVIEW);
  if (modelview) glLoadMatrixf(modelview->data());
}

}  // namespace

int main(int argc, char** argv) {
  const viper::test_program::Options options = viper::test_program::parseOptions(
      "gl_legacy_program", argc, argv, true, [](const std::string&, const std::string&) { return false; });
  const int width = options.width, height = options.height, frames = options.frames;
  const std::string& out = options.out;
  const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  const viper::test_program::EglPbuffer pbuffer =
      viper::test_program::makeCurrentPbuffer("gl_legacy_program", width, height, ctx_attrs, "GL 3.0 context");
  EGLDisplay dpy = pbuffer.display;
  EGLSurface surface = pbuffer.surface;
  auto buffer_data = reinterpret_cast<PFNGLBUFFERDATAARBPROC>(eglGetProcAddress("glBufferDataARB"));
  if (!buffer_data) die("no glBufferDataARB");

  const GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, kVs));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, kFs));
  glLinkProgram(program);
  const GLint color = glGetUniformLocation(program, "u_color");
  const GLuint refused = glCreateProgram();
  glAttachShader(refused, compile(GL_VERTEX_SHADER, kRefusedVs));
  glAttachShader(refused, compile(GL_FRAGMENT_SHADER, kRefusedFs));
  glLinkProgram(refused);

  // 36-byte records as Irrlicht's S3DVertex (position, normal, color, texture coordinates).
  struct Vertex {
    float pos[3], normal[3];
    uint32_t color;
    float uv[2];
  };
  const Vertex quad[4] = {{{-1, -1, 0}, {0, 0, 1}, 0, {0, 0}}, {{1, -1, 0}, {0, 0, 1}, 0, {1, 0}},
                          {{1, 1, 0}, {0, 0, 1}, 0, {1, 1}},   {{-1, 1, 0}, {0, 0, 1}, 0, {0, 1}}};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  const Vertex unrolled[6] = {quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]};
  GLuint buffers[2];
  glGenBuffers(2, buffers);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  buffer_data(GL_ARRAY_BUFFER, sizeof(quad), quad, GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
  buffer_data(GL_ELEMENT_ARRAY_BUFFER, sizeof(indices), indices, GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  glEnableClientState(GL_VERTEX_ARRAY);

  std::vector<uint8_t> pixels(static_cast<size_t>(width) * height * 4);
  const Eigen::Matrix4f proj = es::projection();
  for (int f = 0; f < frames; ++f) {
    const Eigen::Matrix4f view = es::view(f);
    glViewport(0, 0, width, height);
    glClearColor(0.1f, 0.1f, 0.2f, 1.0f);
    glEnable(GL_DEPTH_TEST);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    // The sky: fixed function, the camera's projection and an identity view (drawn around the
    // camera), 40 units away at the top right of the image (NDC (0.85, 0.8), 0.08 in size).
    glUseProgram(0);
    loadMatrices(proj, Eigen::Matrix4f::Identity());
    const float sky = 40.0f;
    glTranslatef(0.85f * sky / proj(0, 0), 0.8f * sky / proj(1, 1), -sky);
    glScalef(0.08f * sky / proj(0, 0), 0.08f * sky / proj(1, 1), 1.0f);
    glColor4f(0.5f, 0.7f, 1.0f, 1.0f);
    glVertexPointer(3, GL_FLOAT, sizeof(Vertex), quad[0].pos);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices);
    loadMatrices(proj, std::nullopt);
    glUseProgram(program);
    for (int k = 0; k < es::kInstances; ++k) {
      glUniform4f(color, 0.3f + 0.3f * k, 0.5f, 0.8f - 0.3f * k, 1.0f);
      glLoadMatrixf(view.data());
      if (k < 2) {
        const Eigen::Matrix4f world = es::world(k, f);
        glMultMatrixf(world.data());
        if (k == 1) {
          glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
          glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
        }
        glVertexPointer(3, GL_FLOAT, sizeof(Vertex), k == 1 ? nullptr : quad[0].pos);
        glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, k == 1 ? nullptr : indices);
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
      } else {
        // The same world as T * R * S with the matrix-stack calls.
        const Eigen::Vector3f o = es::origin(k, f), s = es::scale(k);
        const Eigen::AngleAxisf r(es::rotation(k, f).conjugate());
        glPushMatrix();
        glTranslatef(o.x(), o.y(), o.z());
        glRotatef(r.angle() * 180.0f / static_cast<float>(M_PI), r.axis().x(), r.axis().y(), r.axis().z());
        glScalef(s.x(), s.y(), s.z());
        glVertexPointer(3, GL_FLOAT, sizeof(Vertex), unrolled[0].pos);
        glDrawArrays(GL_TRIANGLES, 0, 6);
        glPopMatrix();
      }
    }
    // A line loop below the quads: recorded, without a mesh.
    glUniform4f(color, 1.0f, 1.0f, 1.0f, 1.0f);
    glLoadMatrixf(view.data());
    glTranslatef(0.0f, -1.3f, -1.0f);
    glScalef(0.3f, 0.3f, 0.3f);
    glVertexPointer(3, GL_FLOAT, sizeof(Vertex), quad[0].pos);
    glDrawArrays(GL_LINE_LOOP, 0, 4);
    // A "particle": fixed function, writing depth, in front of quad 0 (around its point (0.5, 0.5)),
    // as Minetest draws the particles of a node being dug.
    // It lies on the camera ray through that point, at the eye depth whose NDC z is -0.9, and is
    // kParticleHalf (NDC) in size; the camera's projection, an identity view.
    glUseProgram(0);
    const Eigen::Vector4f e = view * es::world(0, f) * Eigen::Vector4f(0.5f, 0.5f, 0.0f, 1.0f);
    const float depth = proj(2, 3) / (0.9f - proj(2, 2));  // eye z: (A z + B) / -z = -0.9
    const float along = depth / e.z();
    loadMatrices(proj, Eigen::Matrix4f::Identity());
    glTranslatef(along * e.x(), along * e.y(), depth);
    glScalef(es::kParticleHalf * -depth / proj(0, 0), es::kParticleHalf * -depth / proj(1, 1), 1.0f);
    glColor4f(0.9f, 0.5f, 0.1f, 1.0f);
    glVertexPointer(3, GL_FLOAT, sizeof(Vertex), quad[0].pos);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices);
    loadMatrices(proj, view);
    glTranslatef(0.0f, -1.3f, -1.0f);
    glScalef(0.3f, 0.3f, 0.3f);
    // The quad whose shader the layer does not rewrite.
    glUseProgram(refused);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices);
    glUseProgram(program);
    // The wielded item: depth cleared, a quad right in front of the camera (lower right).
    glClear(GL_DEPTH_BUFFER_BIT);
    glLoadIdentity();
    glTranslatef(0.6f, -0.5f, -1.5f);
    glScalef(0.2f, 0.2f, 0.2f);
    glUniform4f(color, 0.9f, 0.2f, 0.9f, 1.0f);
    glVertexPointer(3, GL_FLOAT, sizeof(Vertex), quad[0].pos);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices);
    // The HUD: fixed function, no program (its color goes to every draw buffer).
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
    loadMatrices(Eigen::Matrix4f::Identity(), Eigen::Matrix4f::Identity());
    glColor4f(1.0f, 0.9f, 0.1f, 1.0f);
    glTranslatef(es::kOverlayX, es::kOverlayY, 0.0f);
    glScalef(es::kOverlayHalf, es::kOverlayHalf, 1.0f);
    glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices);

    if (f == frames - 1 && !out.empty()) {
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
    }
    eglSwapBuffers(dpy, surface);
  }
  if (glGetError() != GL_NO_ERROR) die("GL error");
  if (!out.empty()) {
    std::ofstream file(out, std::ios::binary);
    file.write(reinterpret_cast<const char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  }
  return 0;
}
