// OpenGL 1.x test program without any shader, as old programs draw: per frame, a quad from a
// conventional vertex array in client memory (glVertexPointer, glDrawArrays) and a triangle in
// immediate mode (glBegin/glEnd), placed with the fixed-function matrix stack, depth tested. The
// capture layer records both (ids from their id passes); test_capture_verdict checks them, and
// what `capture` says of them.
//   gl_fixed_function_program [--size WxH] [--frames N]
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include "egl_pbuffer.h"
#include "gl_common/sanitizer_options.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

[[noreturn]] void die(const std::string& what) { viper::test_program::die("gl_fixed_function_program", what); }

}  // namespace

int main(int argc, char** argv) {
  const viper::test_program::Options options = viper::test_program::parseOptions(
      "gl_fixed_function_program", argc, argv, false, [](const std::string&, const std::string&) { return false; });
  const int width = options.width, height = options.height, frames = options.frames;
  const EGLint ctx_attrs[] = {EGL_NONE};  // the default: a compatibility context
  const viper::test_program::EglPbuffer pbuffer = viper::test_program::makeCurrentPbuffer(
      "gl_fixed_function_program", width, height, ctx_attrs, "OpenGL context");

  const GLfloat quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0};
  glEnable(GL_DEPTH_TEST);
  glViewport(0, 0, width, height);
  for (int f = 0; f < frames; ++f) {
    glClearColor(0.1f, 0.2f, 0.3f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-0.1, 0.1, -0.075, 0.075, 0.1, 100.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glTranslatef(-0.6f + 0.1f * f, 0.0f, -4.0f);
    glColor3f(0.8f, 0.3f, 0.2f);
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, quad);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glDisableClientState(GL_VERTEX_ARRAY);
    glLoadIdentity();
    glTranslatef(1.2f, 0.0f, -5.0f);
    glColor3f(0.2f, 0.8f, 0.3f);
    glBegin(GL_TRIANGLES);
    glVertex3f(-1.0f, -1.0f, 0.0f);
    glVertex3f(1.0f, -1.0f, 0.0f);
    glVertex3f(0.0f, 1.0f, 0.0f);
    glEnd();
    eglSwapBuffers(pbuffer.display, pbuffer.surface);
  }
  if (glGetError() != GL_NO_ERROR) die("GL error");
  return 0;
}
