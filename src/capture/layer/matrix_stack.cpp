#include "matrix_stack.h"

#include <Eigen/Geometry>

namespace viper {
namespace capture {

void ModelViewTracker::load(const GlMatrix& m) {
  if (!modelview_) return;
  stack_.back().view = m;
  stack_.back().world.setIdentity();
}

void ModelViewTracker::multiply(const GlMatrix& m) {
  if (modelview_) stack_.back().world = stack_.back().world * m;
}

void ModelViewTracker::push() {
  if (modelview_) stack_.push_back(stack_.back());
}

void ModelViewTracker::pop() {
  if (modelview_ && stack_.size() > 1) stack_.pop_back();
}

GlMatrix ModelViewTracker::translation(double x, double y, double z) {
  GlMatrix m = GlMatrix::Identity();
  m.block<3, 1>(0, 3) = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  return m;
}

GlMatrix ModelViewTracker::rotation(double degrees, double x, double y, double z) {
  GlMatrix m = GlMatrix::Identity();
  const Eigen::Vector3d axis(x, y, z);
  if (axis.norm() == 0.0) return m;
  m.block<3, 3>(0, 0) = Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix().cast<float>();
  return m;
}

GlMatrix ModelViewTracker::scaling(double x, double y, double z) {
  return Eigen::Vector4f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 1.0f).asDiagonal();
}

}  // namespace capture
}  // namespace viper
