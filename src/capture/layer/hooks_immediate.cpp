// Exported compatibility-profile entry points of immediate mode (glBegin, glVertex*, glEnd) and
// display lists (glNewList, glEndList, glCallList(s)): a glBegin/glEnd without a program is
// recorded from the vertices passed in between (Interceptor::beginImmediate); draws made while a
// display list is being made are not recorded (Interceptor::notRecordedInList).
#include "hooks.h"
#include "interceptor.h"

using viper::capture::gl;
using viper::capture::Interceptor;

namespace {

// A vertex between glBegin and glEnd (glVertex2 has z 0, glVertex2 and 3 have w 1).
inline void vertex(float x, float y, float z, float w) {
  if (Interceptor* i = Interceptor::active()) i->immediateVertex(x, y, z, w);
}

}  // namespace

VIPER_EXPORT void glBegin(GLenum mode) {
  if (Interceptor* i = Interceptor::active()) i->beginImmediate(mode);
  gl().Begin(mode);
}
VIPER_EXPORT void glEnd(void) {
  gl().End();
  if (Interceptor* i = Interceptor::active()) i->endImmediate();
}
VIPER_EXPORT void glNewList(GLuint list, GLenum mode) {
  gl().NewList(list, mode);
  if (Interceptor* i = Interceptor::active()) i->newList(mode);
}
VIPER_EXPORT void glEndList(void) {
  gl().EndList();
  if (Interceptor* i = Interceptor::active()) i->newList(0);
}
VIPER_EXPORT void glCallList(GLuint list) {
  if (Interceptor* i = Interceptor::active()) i->beforeUnrecordableDraw("display-list (glCallList)");
  gl().CallList(list);
}
VIPER_EXPORT void glCallLists(GLsizei n, GLenum type, const void* lists) {
  if (Interceptor* i = Interceptor::active()) i->beforeUnrecordableDraw("display-list (glCallLists)");
  gl().CallLists(n, type, lists);
}

VIPER_EXPORT void glVertex2s(GLshort x, GLshort y) {
  gl().Vertex2s(x, y);
  vertex(static_cast<float>(x), static_cast<float>(y), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2sv(const GLshort* v) {
  gl().Vertex2sv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2i(GLint x, GLint y) {
  gl().Vertex2i(x, y);
  vertex(static_cast<float>(x), static_cast<float>(y), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2iv(const GLint* v) {
  gl().Vertex2iv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2f(GLfloat x, GLfloat y) {
  gl().Vertex2f(x, y);
  vertex(static_cast<float>(x), static_cast<float>(y), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2fv(const GLfloat* v) {
  gl().Vertex2fv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2d(GLdouble x, GLdouble y) {
  gl().Vertex2d(x, y);
  vertex(static_cast<float>(x), static_cast<float>(y), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex2dv(const GLdouble* v) {
  gl().Vertex2dv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), 0.0f, 1.0f);
}
VIPER_EXPORT void glVertex3s(GLshort x, GLshort y, GLshort z) {
  gl().Vertex3s(x, y, z);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 1.0f);
}
VIPER_EXPORT void glVertex3sv(const GLshort* v) {
  gl().Vertex3sv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 1.0f);
}
VIPER_EXPORT void glVertex3i(GLint x, GLint y, GLint z) {
  gl().Vertex3i(x, y, z);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 1.0f);
}
VIPER_EXPORT void glVertex3iv(const GLint* v) {
  gl().Vertex3iv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 1.0f);
}
VIPER_EXPORT void glVertex3f(GLfloat x, GLfloat y, GLfloat z) {
  gl().Vertex3f(x, y, z);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 1.0f);
}
VIPER_EXPORT void glVertex3fv(const GLfloat* v) {
  gl().Vertex3fv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 1.0f);
}
VIPER_EXPORT void glVertex3d(GLdouble x, GLdouble y, GLdouble z) {
  gl().Vertex3d(x, y, z);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 1.0f);
}
VIPER_EXPORT void glVertex3dv(const GLdouble* v) {
  gl().Vertex3dv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 1.0f);
}
VIPER_EXPORT void glVertex4s(GLshort x, GLshort y, GLshort z, GLshort w) {
  gl().Vertex4s(x, y, z, w);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(w));
}
VIPER_EXPORT void glVertex4sv(const GLshort* v) {
  gl().Vertex4sv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), static_cast<float>(v[3]));
}
VIPER_EXPORT void glVertex4i(GLint x, GLint y, GLint z, GLint w) {
  gl().Vertex4i(x, y, z, w);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(w));
}
VIPER_EXPORT void glVertex4iv(const GLint* v) {
  gl().Vertex4iv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), static_cast<float>(v[3]));
}
VIPER_EXPORT void glVertex4f(GLfloat x, GLfloat y, GLfloat z, GLfloat w) {
  gl().Vertex4f(x, y, z, w);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(w));
}
VIPER_EXPORT void glVertex4fv(const GLfloat* v) {
  gl().Vertex4fv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), static_cast<float>(v[3]));
}
VIPER_EXPORT void glVertex4d(GLdouble x, GLdouble y, GLdouble z, GLdouble w) {
  gl().Vertex4d(x, y, z, w);
  vertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(w));
}
VIPER_EXPORT void glVertex4dv(const GLdouble* v) {
  gl().Vertex4dv(v);
  vertex(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), static_cast<float>(v[3]));
}

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForImmediate(const char* name) {
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(glBegin),      VIPER_ENTRY(glCallList),   VIPER_ENTRY(glCallLists),
      VIPER_ENTRY(glEnd),
      VIPER_ENTRY(glNewList),
      VIPER_ENTRY(glEndList),
      VIPER_ENTRY(glVertex2s),
      VIPER_ENTRY(glVertex2sv),
      VIPER_ENTRY(glVertex2i),
      VIPER_ENTRY(glVertex2iv),
      VIPER_ENTRY(glVertex2f),
      VIPER_ENTRY(glVertex2fv),
      VIPER_ENTRY(glVertex2d),
      VIPER_ENTRY(glVertex2dv),
      VIPER_ENTRY(glVertex3s),
      VIPER_ENTRY(glVertex3sv),
      VIPER_ENTRY(glVertex3i),
      VIPER_ENTRY(glVertex3iv),
      VIPER_ENTRY(glVertex3f),
      VIPER_ENTRY(glVertex3fv),
      VIPER_ENTRY(glVertex3d),
      VIPER_ENTRY(glVertex3dv),
      VIPER_ENTRY(glVertex4s),
      VIPER_ENTRY(glVertex4sv),
      VIPER_ENTRY(glVertex4i),
      VIPER_ENTRY(glVertex4iv),
      VIPER_ENTRY(glVertex4f),
      VIPER_ENTRY(glVertex4fv),
      VIPER_ENTRY(glVertex4d),
      VIPER_ENTRY(glVertex4dv),
  };
#undef VIPER_ENTRY
  return findHook(kEntries, name);
}

}  // namespace capture
}  // namespace viper
