// Exported compatibility-profile entry points: the fixed-function matrix stack (tracked for
// profiles with `matrix_stack`) and the accumulation buffer. (Immediate mode and display lists are
// in hooks_immediate.cpp.) (The extension names of the core functions, such as
// ARB_vertex_buffer_object's, are in hooks_gl.cpp.)
#include "hooks.h"
#include "interceptor.h"

#include <cstring>

using viper::GlMatrix;
using viper::capture::gl;
using viper::capture::Interceptor;
using viper::capture::ModelViewTracker;

namespace {

inline ModelViewTracker* tracker() {
  Interceptor* i = Interceptor::active();
  // (Not while a display list is made with GL_COMPILE: its matrix calls run when it is called.)
  return i && !i->compilingOnly() ? &i->modelView() : nullptr;
}

template <typename T>
GlMatrix matrixOf(const T* m) {
  GlMatrix out;
  for (int k = 0; k < 16; ++k) out.data()[k] = static_cast<float>(m[k]);  // column-major, as GL's
  return out;
}

}  // namespace

VIPER_EXPORT void glMatrixMode(GLenum mode) {
  gl().MatrixMode(mode);
  if (ModelViewTracker* t = tracker()) t->matrixMode(mode);
}
VIPER_EXPORT void glLoadIdentity(void) {
  gl().LoadIdentity();
  if (ModelViewTracker* t = tracker()) t->load(GlMatrix::Identity());
}
VIPER_EXPORT void glPushMatrix(void) {
  gl().PushMatrix();
  if (ModelViewTracker* t = tracker()) t->push();
}
VIPER_EXPORT void glPopMatrix(void) {
  gl().PopMatrix();
  if (ModelViewTracker* t = tracker()) t->pop();
}

// The entry points with a float and a double form (suffix f and d).
#define VIPER_MATRIX_HOOKS(s, T)                                                                  \
  VIPER_EXPORT void glLoadMatrix##s(const T* m) {                                                \
    gl().LoadMatrix##s(m);                                                                        \
    if (ModelViewTracker* t = tracker()) t->load(matrixOf(m));                                    \
  }                                                                                               \
  VIPER_EXPORT void glMultMatrix##s(const T* m) {                                                \
    gl().MultMatrix##s(m);                                                                        \
    if (ModelViewTracker* t = tracker()) t->multiply(matrixOf(m));                                \
  }                                                                                               \
  VIPER_EXPORT void glTranslate##s(T x, T y, T z) {                                              \
    gl().Translate##s(x, y, z);                                                                   \
    if (ModelViewTracker* t = tracker()) t->multiply(ModelViewTracker::translation(x, y, z));     \
  }                                                                                               \
  VIPER_EXPORT void glScale##s(T x, T y, T z) {                                                  \
    gl().Scale##s(x, y, z);                                                                       \
    if (ModelViewTracker* t = tracker()) t->multiply(ModelViewTracker::scaling(x, y, z));         \
  }                                                                                               \
  VIPER_EXPORT void glRotate##s(T angle, T x, T y, T z) {                                        \
    gl().Rotate##s(angle, x, y, z);                                                               \
    if (ModelViewTracker* t = tracker()) t->multiply(ModelViewTracker::rotation(angle, x, y, z)); \
  }
VIPER_MATRIX_HOOKS(f, GLfloat)
VIPER_MATRIX_HOOKS(d, GLdouble)
#undef VIPER_MATRIX_HOOKS

VIPER_EXPORT void glAccum(GLenum op, GLfloat value) {
  if (Interceptor* i = Interceptor::active()) return i->accum(op, value);
  gl().Accum(op, value);
}

namespace viper {
namespace capture {

VIPER_NO_SANITIZE void* wrapperForLegacy(const char* name) {
#define VIPER_ENTRY(f) VIPER_HOOK_ENTRY(f)
  static const HookEntry kEntries[] = {
      VIPER_ENTRY(glMatrixMode),   VIPER_ENTRY(glLoadIdentity),     VIPER_ENTRY(glLoadMatrixf),
      VIPER_ENTRY(glLoadMatrixd),  VIPER_ENTRY(glMultMatrixf),      VIPER_ENTRY(glMultMatrixd),
      VIPER_ENTRY(glPushMatrix),   VIPER_ENTRY(glPopMatrix),        VIPER_ENTRY(glTranslatef),
      VIPER_ENTRY(glTranslated),   VIPER_ENTRY(glScalef),           VIPER_ENTRY(glScaled),
      VIPER_ENTRY(glRotatef),      VIPER_ENTRY(glRotated),          VIPER_ENTRY(glAccum),
  };
#undef VIPER_ENTRY
  return findHook(kEntries, name);
}

}  // namespace capture
}  // namespace viper
