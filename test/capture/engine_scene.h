// The scene of the engine-style GL test program (gl_engine_program.cpp), shared with the test that
// checks its capture: what a real engine does and the plain test program does not. Quads drawn as
// instances of one instanced draw, each placed by origin, quaternion and half-float scale
// attributes in a persistently mapped buffer; view and projection in a std140 uniform block.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>

namespace viper {
namespace engine_scene {

constexpr int kInstances = 3;
/// The 2D overlay quad (HUD): its centre and half size in normalised device coordinates.
constexpr float kOverlayX = -0.75f, kOverlayY = -0.75f, kOverlayHalf = 0.15f;
constexpr float kParticleHalf = 0.04f;  ///< gl_legacy_program: half size of its "particle", NDC

inline Eigen::Vector3f origin(int instance, uint64_t frame) {
  return Eigen::Vector3f(-1.25f + 1.25f * instance, 0.1f * static_cast<float>(frame % 5), -0.2f * instance);
}
/// Unit quaternion (x, y, z, w) the program uploads; its shader rotates by the conjugate
/// (v + 2 cross(cross(v, q.xyz) + q.w v, q.xyz), as SuperTuxKart's does).
inline Eigen::Quaternionf rotation(int instance, uint64_t frame) {
  return Eigen::Quaternionf(Eigen::AngleAxisf(0.3f * instance + 0.05f * static_cast<float>(frame),
                                              Eigen::Vector3f(0.2f, 0.3f, 1.0f).normalized()));
}
inline Eigen::Vector3f scale(int instance) { return Eigen::Vector3f(0.5f, 0.375f + 0.125f * instance, 1.0f); }

/// The world matrix an instance's vertices see: T(origin) * R(conjugate of the uploaded q) * S.
inline Eigen::Matrix4f world(int instance, uint64_t frame) {
  Eigen::Affine3f m = Eigen::Affine3f::Identity();
  m.translate(origin(instance, frame));
  m.rotate(rotation(instance, frame).conjugate());
  m.scale(scale(instance));
  return m.matrix();
}

/// Perspective camera 6 m back, looking down -z.
inline Eigen::Matrix4f view(uint64_t frame) {
  Eigen::Matrix4f v = Eigen::Matrix4f::Identity();
  v(0, 3) = -0.05f * static_cast<float>(frame);
  v(2, 3) = -6.0f;
  return v;
}
inline Eigen::Matrix4f projection() {
  const float n = 0.5f, f = 50.0f, t = 1.0f / std::tan(0.4f), aspect = 4.0f / 3.0f;
  Eigen::Matrix4f p = Eigen::Matrix4f::Zero();
  p(0, 0) = t / aspect, p(1, 1) = t;
  p(2, 2) = (f + n) / (n - f), p(2, 3) = 2 * f * n / (n - f), p(3, 2) = -1;
  return p;
}

}  // namespace engine_scene
}  // namespace viper
