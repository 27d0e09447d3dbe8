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
template <typename T>
void vertex(T x, T y, T z = 0, T w = 1) {
  if (Interceptor* i = Interceptor::active())
    i->immediateVertex(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(w));
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

// glVertex{2,3,4}{s,i,f,d}[v]: X(suffix, type) for each of glVertex's parameter types.
#define VIPER_VERTEX_TYPES(X) X(s, GLshort) X(i, GLint) X(f, GLfloat) X(d, GLdouble)
#define VIPER_VERTEX_HOOKS(s, T)                                                                \
  VIPER_EXPORT void glVertex2##s(T x, T y) {                                                    \
    gl().Vertex2##s(x, y);                                                                      \
    vertex(x, y);                                                                               \
  }                                                                                             \
  VIPER_EXPORT void glVertex2##s##v(const T* v) {                                               \
    gl().Vertex2##s##v(v);                                                                      \
    vertex(v[0], v[1]);                                                                         \
  }                                                                                             \
  VIPER_EXPORT void glVertex3##s(T x, T y, T z) {                                               \
    gl().Vertex3##s(x, y, z);                                                                   \
    vertex(x, y, z);                                                                            \
  }                                                                                             \
  VIPER_EXPORT void glVertex3##s##v(const T* v) {                                               \
    gl().Vertex3##s##v(v);                                                                      \
    vertex(v[0], v[1], v[2]);                                                                   \
  }                                                                                             \
  VIPER_EXPORT void glVertex4##s(T x, T y, T z, T w) {                                          \
    gl().Vertex4##s(x, y, z, w);                                                                \
    vertex(x, y, z, w);                                                                         \
  }                                                                                             \
  VIPER_EXPORT void glVertex4##s##v(const T* v) {                                               \
    gl().Vertex4##s##v(v);                                                                      \
    vertex(v[0], v[1], v[2], v[3]);                                                             \
  }
VIPER_VERTEX_TYPES(VIPER_VERTEX_HOOKS)
#undef VIPER_VERTEX_HOOKS

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForImmediate(const char* name) {
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(glBegin),      VIPER_ENTRY(glCallList),   VIPER_ENTRY(glCallLists),
      VIPER_ENTRY(glEnd),        VIPER_ENTRY(glNewList),    VIPER_ENTRY(glEndList),
#define VIPER_VERTEX_ENTRIES(s, T)                                                           \
  VIPER_ENTRY(glVertex2##s), VIPER_ENTRY(glVertex2##s##v), VIPER_ENTRY(glVertex3##s),        \
      VIPER_ENTRY(glVertex3##s##v), VIPER_ENTRY(glVertex4##s), VIPER_ENTRY(glVertex4##s##v),
      VIPER_VERTEX_TYPES(VIPER_VERTEX_ENTRIES)
#undef VIPER_VERTEX_ENTRIES
  };
#undef VIPER_ENTRY
  return findHook(kEntries, name);
}

}  // namespace capture
}  // namespace viper
