// Scenarios of gl_stress_program (its header says what each does) in which the program passes its
// matrices otherwise than as world, view and projection uniforms, or uses the compatibility
// profile: combined_matrices, fixed_function, window_queries, extension_names.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include "gl_stress_support.h"
#include "stress_scene.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

namespace viper {
namespace stress_program {

namespace ss = viper::stress_scene;

// Engines that pass combined matrices: a background in world space drawn with a view-projection
// alone (its vertices placed on the CPU), objects 0 and 1 with a model-view and a projection,
// objects 2 and 3 with a model-view-projection alone. The layer recovers the frame's camera and
// each world from them (the profile's model_view, view_projection, model_view_projection and
// world_space).
void combinedMatrices(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint background = program(R"(#version 330 core
uniform mat4 u_viewproj;
layout(location = 0) in vec3 a_pos;
void main() { gl_Position = u_viewproj * vec4(a_pos, 1.0); }
)", kColourFs);
  const GLuint model_view = program(R"(#version 330 core
uniform mat4 u_modelview;
uniform mat4 u_projection;
layout(location = 0) in vec3 a_pos;
void main() { gl_Position = u_projection * (u_modelview * vec4(a_pos, 1.0)); }
)", kColourFs);
  const GLuint mvp = program(R"(#version 330 core
uniform mat4 u_mvp;
layout(location = 0) in vec3 a_pos;
void main() { gl_Position = u_mvp * vec4(a_pos, 1.0); }
)", kColourFs);
  const Quad q = makeQuad();
  // The background quad's vertices in world space: the unit quad scaled by 0.95 at kBackgroundZ.
  const Quad world_quad = makeQuad();
  const float z = ss::kBackgroundZ;
  const float placed[12] = {-0.95f, -0.95f, z, 0.95f, -0.95f, z, 0.95f, 0.95f, z, -0.95f, 0.95f, z};
  GL(glBindBuffer(GL_ARRAY_BUFFER, world_quad.vbo));
  GL(glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof(placed), placed));
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    const Eigen::Matrix4f v = ss::view(f), p = ss::projection();
    GL(glUseProgram(background));
    GL(glBindVertexArray(world_quad.vao));
    setMatrix(background, "u_viewproj", p * v);
    GL(glUniform4f(GLV(glGetUniformLocation(background, "u_colour")), 0.5f, 0.5f, 0.5f, 1.0f));
    GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      const GLuint prog = k < 2 ? model_view : mvp;
      GL(glUseProgram(prog));
      if (k < 2) {
        setMatrix(prog, "u_modelview", v * ss::world(k));
        setMatrix(prog, "u_projection", p);
      } else {
        setMatrix(prog, "u_mvp", p * v * ss::world(k));
      }
      setColour(prog, k);
      GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

// OpenGL 1.x without a program (compatibility profile): the objects from the conventional vertex
// array in client memory (two with glDrawArrays, one with glDrawElements and indices in client
// memory) and in immediate mode (object 2: glBegin, glVertex3fv, glEnd), the projection loaded into GL_PROJECTION, the view multiplied onto the identity at the
// bottom of GL_MODELVIEW (as gluLookAt does) and each world multiplied onto it between
// glPushMatrix and glPopMatrix (the textbook pattern), colour from glColor4fv. Object 1
// is alpha tested and stencilled (its stencil replaced where drawn), object 3 drawn while an
// occlusion query counts its samples, printed ("query: ...") for the test to compare. After them,
// a display list made before the first frame (GL_COMPILE: a translation and a triangle in
// immediate mode, below the objects) is called.
void fixedFunction(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize, EGL_NO_CONTEXT, /*compatibility=*/true);
  makeCurrent(s);
  constexpr GLenum kModelView = 0x1700, kProjection = 0x1701, kVertexArray = 0x8074, kAlphaTest = 0x0BC0;
  using Enum = void (*)(GLenum);
  using Matrix = void (*)(const GLfloat*);
  using Void = void (*)();
  using Pointer = void (*)(GLint, GLenum, GLsizei, const void*);
  using Colour = void (*)(const GLfloat*);
  using AlphaFunc = void (*)(GLenum, GLfloat);
  auto proc = [](const char* name) {
    void (*f)() = eglGetProcAddress(name);
    if (!f) die(std::string("no ") + name + " from eglGetProcAddress");
    return f;
  };
  auto matrix_mode = reinterpret_cast<Enum>(proc("glMatrixMode"));
  auto load_matrix = reinterpret_cast<Matrix>(proc("glLoadMatrixf"));
  auto mult_matrix = reinterpret_cast<Matrix>(proc("glMultMatrixf"));
  auto load_identity = reinterpret_cast<Void>(proc("glLoadIdentity"));
  auto push_matrix = reinterpret_cast<Void>(proc("glPushMatrix"));
  auto pop_matrix = reinterpret_cast<Void>(proc("glPopMatrix"));
  auto enable_client_state = reinterpret_cast<Enum>(proc("glEnableClientState"));
  auto vertex_pointer = reinterpret_cast<Pointer>(proc("glVertexPointer"));
  auto colour4 = reinterpret_cast<Colour>(proc("glColor4fv"));
  auto alpha_func = reinterpret_cast<AlphaFunc>(proc("glAlphaFunc"));
  using NewList = void (*)(GLuint, GLenum);
  using Vertex = void (*)(const GLfloat*);
  using Translate = void (*)(GLfloat, GLfloat, GLfloat);
  auto gen_lists = reinterpret_cast<GLuint (*)(GLsizei)>(proc("glGenLists"));
  auto new_list = reinterpret_cast<NewList>(proc("glNewList"));
  auto end_list = reinterpret_cast<Void>(proc("glEndList"));
  auto call_list = reinterpret_cast<void (*)(GLuint)>(proc("glCallList"));
  auto begin = reinterpret_cast<Enum>(proc("glBegin"));
  auto end = reinterpret_cast<Void>(proc("glEnd"));
  auto vertex3 = reinterpret_cast<Vertex>(proc("glVertex3fv"));
  auto translate = reinterpret_cast<Translate>(proc("glTranslatef"));
  const GLfloat corners[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const GLfloat triangles[18] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0};
  const GLushort indices[6] = {0, 1, 2, 0, 2, 3};
  GLuint query = 0;
  GL(glGenQueries(1, &query));
  GL(enable_client_state(kVertexArray));
  constexpr GLenum kCompile = 0x1300;
  const GLuint list = gen_lists(1);
  GL(new_list(list, kCompile));
  GL(push_matrix());
  GL(translate(0.0f, -0.5f, 0.0f));
  GL(begin(GL_TRIANGLES));
  for (int v = 0; v < 3; ++v) vertex3(corners + 3 * v);  // (no glGetError between glBegin and glEnd)
  GL(end());
  GL(pop_matrix());
  GL(end_list());
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glClear(GL_STENCIL_BUFFER_BIT));
    GL(matrix_mode(kProjection));
    GL(load_matrix(ss::projection().data()));
    GL(matrix_mode(kModelView));
    GL(load_identity());
    GL(mult_matrix(ss::view(f).data()));
    for (int k = 0; k < 4; ++k) {
      GL(push_matrix());
      GL(mult_matrix(ss::world(k).data()));
      GL(colour4(ss::colour(k).data()));
      if (k == 1) {
        GL(glEnable(kAlphaTest));
        GL(alpha_func(GL_GREATER, 0.5f));
        GL(glEnable(GL_STENCIL_TEST));
        GL(glStencilFunc(GL_ALWAYS, 1, 0xff));
        GL(glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE));
      }
      if (k == 3) GL(glBeginQuery(GL_SAMPLES_PASSED, query));
      if (k < 2) {
        GL(vertex_pointer(3, GL_FLOAT, 0, triangles));
        GL(glDrawArrays(GL_TRIANGLES, 0, 6));
      } else if (k == 2) {
        begin(GL_TRIANGLES);
        for (int v = 0; v < 6; ++v) vertex3(triangles + 3 * v);
        GL(end());
      } else {
        GL(vertex_pointer(3, GL_FLOAT, 0, corners));
        GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, indices));
      }
      if (k == 3) GL(glEndQuery(GL_SAMPLES_PASSED));
      if (k == 1) {
        GL(glDisable(kAlphaTest));
        GL(glDisable(GL_STENCIL_TEST));
      }
      GL(pop_matrix());
    }
    GL(call_list(list));
    GLuint samples = 0;
    GL(glGetQueryObjectuiv(query, GL_QUERY_RESULT, &samples));
    std::printf("query: frame %d, object 3 passed %u samples\n", f, samples);
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

// What a toolkit asks of the window after making its context current (one refused to start when
// GL_DOUBLEBUFFER answered 0 under the layer): the window's properties in every glGet form, its
// attachments, its status, the draw and read buffers, the framebuffer bindings. Printed each
// frame ("window: ..."), for the test to compare with a run without the layer. Frame 2 also
// draws with a framebuffer object of its own bound and deletes it while bound: the GL binds the
// default framebuffer in its place, where the objects then go.
void windowQueries(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize, EGL_NO_CONTEXT, /*compatibility=*/true);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kColourFs);
  const Quad q = makeQuad();
  const GLenum pnames[] = {GL_DOUBLEBUFFER, GL_STEREO, GL_SAMPLES, GL_SAMPLE_BUFFERS,
                           GL_DRAW_BUFFER, GL_DRAW_BUFFER0, GL_DRAW_BUFFER1, GL_DRAW_BUFFER7, GL_READ_BUFFER,
                           GL_DRAW_FRAMEBUFFER_BINDING, GL_READ_FRAMEBUFFER_BINDING,
                           GL_IMPLEMENTATION_COLOR_READ_FORMAT, GL_IMPLEMENTATION_COLOR_READ_TYPE,
                           0x0D52 /*RED_BITS*/, 0x0D55 /*ALPHA_BITS*/, 0x0D56 /*DEPTH_BITS*/, 0x0D57 /*STENCIL_BITS*/,
                           0x0C31 /*RGBA_MODE*/, 0x0C00 /*AUX_BUFFERS*/};
  for (int f = 0; f < frames; ++f) {
    // (Before beginFrame, which causes the program's own error in frame 1: the errors of these
    // queries are read here.)
    std::string line = "window:";
    for (GLenum pname : pnames) {
      GLint i = -1;
      GLint64 i64 = -1;
      GLfloat fl = -1;
      GLdouble d = -1;
      GLboolean b = 7;
      GL(glGetIntegerv(pname, &i));
      GL(glGetInteger64v(pname, &i64));
      GL(glGetFloatv(pname, &fl));
      GL(glGetDoublev(pname, &d));
      GL(glGetBooleanv(pname, &b));
      line += " " + std::to_string(i) + "/" + std::to_string(i64) + "/" + std::to_string(static_cast<int>(fl)) +
              "/" + std::to_string(static_cast<int>(d)) + "/" + std::to_string(b);
    }
    GLint doublebuffer = 0;
    GL(glGetIntegerv(GL_DOUBLEBUFFER, &doublebuffer));
    const GLenum colour = doublebuffer ? GL_BACK_LEFT : GL_FRONT_LEFT;
    for (GLenum attachment : {colour, GLenum(GL_DEPTH), GLenum(GL_STENCIL)})
      for (GLenum pname : {GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE,
                           GL_FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE,
                           GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING}) {
        GLint v = -1;
        glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, attachment, pname, &v);
        line += " " + std::to_string(v) + ":" + std::to_string(glGetError());
      }
    GLint samples = -1;
    glGetFramebufferParameteriv(GL_DRAW_FRAMEBUFFER, GL_SAMPLES, &samples);
    line += " fbsamples " + std::to_string(samples) + ":" + std::to_string(glGetError());
    line += " status " + std::to_string(GLV(glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER)));
    std::printf("%s\n", line.c_str());
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    if (f == 2) {
      GLuint fb = 0;
      GL(glGenFramebuffers(1, &fb));
      GL(glBindFramebuffer(GL_FRAMEBUFFER, fb));
      GL(glDeleteFramebuffers(1, &fb));  // the default framebuffer is bound again
      GLint bound = -1;
      GL(glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound));
      std::printf("window: bound after the delete %d\n", bound);
    }
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

// An older engine's calls: the extension names of the core functions (glBindFramebufferEXT,
// glDrawRangeElementsEXT, glBindBufferARB, glTexSubImage2DEXT...), found with eglGetProcAddress,
// and a 256x256 GL_ALPHA texture updated from memory that ends where a page the program cannot
// read begins (the layer once read 4 bytes a pixel of it and crashed the game). Each frame first
// draws into a framebuffer object of its own, then binds the default framebuffer again with the
// EXT name and draws the objects there.
void extensionNames(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize, EGL_NO_CONTEXT, /*compatibility=*/true);
  makeCurrent(s);
  using BindFramebuffer = void (*)(GLenum, GLuint);
  using DrawRangeElements = void (*)(GLenum, GLuint, GLuint, GLsizei, GLenum, const void*);
  using TexSubImage2D = void (*)(GLenum, GLint, GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, const void*);
  using ActiveTexture = void (*)(GLenum);
  auto bind_fb = reinterpret_cast<BindFramebuffer>(eglGetProcAddress("glBindFramebufferEXT"));
  auto draw_range = reinterpret_cast<DrawRangeElements>(eglGetProcAddress("glDrawRangeElementsEXT"));
  auto tex_sub = reinterpret_cast<TexSubImage2D>(eglGetProcAddress("glTexSubImage2DEXT"));
  auto active_texture = reinterpret_cast<ActiveTexture>(eglGetProcAddress("glActiveTextureARB"));
  if (!bind_fb || !draw_range || !tex_sub || !active_texture) die("no extension names from eglGetProcAddress");
  const GLuint p = program(kUniformVs, kColourFs);
  const Quad q = makeQuad();
  // The alpha texture's texels: the last byte of a mapping whose next page is unreadable.
  constexpr int kAlphaSize = 256;
  const size_t bytes = size_t(kAlphaSize) * kAlphaSize, page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  const size_t pages = (bytes + page - 1) / page + 1;
  auto* mapping = static_cast<uint8_t*>(mmap(nullptr, pages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  if (mapping == MAP_FAILED || mprotect(mapping + (pages - 1) * page, page, PROT_NONE) != 0) die("no guarded mapping");
  uint8_t* texels = mapping + (pages - 1) * page - bytes;
  GLuint texture = 0, fb = 0, colour = 0;
  GL(active_texture(GL_TEXTURE0));
  GL(glGenTextures(1, &texture));
  GL(glBindTexture(GL_TEXTURE_2D, texture));
  GL(glPixelStorei(GL_UNPACK_ALIGNMENT, 1));
  GL(glTexImage2D(GL_TEXTURE_2D, 0, GL_ALPHA, kAlphaSize, kAlphaSize, 0, GL_ALPHA, GL_UNSIGNED_BYTE, nullptr));
  GL(glGenTextures(1, &colour));
  GL(glBindTexture(GL_TEXTURE_2D, colour));
  GL(glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, ss::kSize, ss::kSize, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr));
  GL(glGenFramebuffers(1, &fb));
  GL(bind_fb(GL_FRAMEBUFFER, fb));
  GL(glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour, 0));
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    std::memset(texels, 40 * f, bytes);
    GL(glBindTexture(GL_TEXTURE_2D, texture));
    GL(tex_sub(GL_TEXTURE_2D, 0, 0, 0, kAlphaSize, kAlphaSize, GL_ALPHA, GL_UNSIGNED_BYTE, texels));
    GL(bind_fb(GL_FRAMEBUFFER, fb));
    GL(glClear(GL_COLOR_BUFFER_BIT));
    GL(bind_fb(GL_FRAMEBUFFER, 0));
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      setMatrix(p, "u_world", ss::world(k));
      setMatrix(p, "u_view", ss::view(f));
      setMatrix(p, "u_proj", ss::projection());
      setColour(p, k);
      GL(draw_range(GL_TRIANGLES, 0, 3, 6, GL_UNSIGNED_SHORT, nullptr));
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

}  // namespace stress_program
}  // namespace viper
