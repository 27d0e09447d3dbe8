// The fixed-function model-view stack of a compatibility context, split the way engines build it
// (profile key `matrix_stack: load_view_mult_world`): the matrix loaded last (glLoadMatrix,
// glLoadIdentity) is the camera's view, and what is multiplied onto it afterwards (glMultMatrix,
// glTranslate, glRotate, glScale) is the drawn object's world. Irrlicht's OpenGL driver loads the
// view and multiplies the world before every draw whose world changes.
#pragma once

#include "viper/capture/capture_frame.h"

#include <vector>

namespace viper {
namespace capture {

class ModelViewTracker {
 public:
  /// glMatrixMode: only GL_MODELVIEW calls change what is tracked.
  void matrixMode(unsigned mode) { modelview_ = mode == 0x1700u; }
  bool inModelView() const { return modelview_; }
  /// glLoadMatrix / glLoadIdentity in GL_MODELVIEW: a new view, the world back to identity.
  void load(const GlMatrix& m);
  /// glMultMatrix / glTranslate / glRotate / glScale in GL_MODELVIEW: applied to the world.
  void multiply(const GlMatrix& m);
  void push();
  /// Pops what push() saved; a pop of the last entry is ignored (GL reports a stack underflow).
  void pop();
  const GlMatrix& view() const { return stack_.back().view; }
  /// The model-view at the bottom of the stack (`matrix_stack: push_world`: the camera, set before
  /// the program pushes each object's world above it).
  GlMatrix base() const { return stack_.front().view * stack_.front().world; }
  const GlMatrix& world() const { return stack_.back().world; }

  /// The translation, rotation (degrees about an axis) and scale matrices of glTranslate,
  /// glRotate and glScale.
  static GlMatrix translation(double x, double y, double z);
  static GlMatrix rotation(double degrees, double x, double y, double z);
  static GlMatrix scaling(double x, double y, double z);

 private:
  struct Entry {
    GlMatrix view = GlMatrix::Identity();
    GlMatrix world = GlMatrix::Identity();
  };
  std::vector<Entry> stack_{1};
  bool modelview_ = true;
};

}  // namespace capture
}  // namespace viper
