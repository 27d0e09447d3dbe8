// What the stress program (gl_stress_program.cpp) draws, shared with the test that checks its
// capture (test_capture_stress.cpp): in every scenario, objects are quads, one per cell of a 4 x 4
// grid over a square image, each its own draw (or instance, or indirect command) in cell order,
// in a colour of its own, through an orthographic camera.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>

namespace viper {
namespace stress_scene {

constexpr int kSize = 64;        ///< image width and height
constexpr int kCell = kSize / 4;  ///< grid cell, pixels
constexpr int kFrames = 4;        ///< frames each scenario swaps (exit_thread: at least)
constexpr float kHalf = 0.2f;     ///< half size of an object's quad, normalised device units
constexpr float kBackgroundZ = -1.0f;  ///< blend_depth: the background's plane, behind the objects (z = 0)

/// Centre of cell k in normalised device coordinates, moved right by `shift`.
inline Eigen::Vector2f cellCentre(int k, float shift = 0.0f) {
  return Eigen::Vector2f(-0.75f + 0.5f * static_cast<float>(k % 4) + shift, 0.75f - 0.5f * static_cast<float>(k / 4));
}
/// Pixel (column, row from the top) at the centre of cell k.
inline int centrePixel(int k) { return (kCell / 2 + kCell * (k / 4)) * kSize + kCell / 2 + kCell * (k % 4); }
/// Per-frame shift of the scenarios whose geometry moves (persistent, threads).
inline float frameShift(uint64_t frame) { return 0.02f * static_cast<float>(frame % 4); }

/// Object k's colour, RGBA8-exact.
inline Eigen::Vector4f colour(int k) {
  return Eigen::Vector4f((40 + 13 * k) / 255.0f, (200 - 11 * k) / 255.0f, (90 + 29 * (k % 5)) / 255.0f, 1.0f);
}

/// World of object k: the unit quad (-1..1, z = 0) scaled to kHalf at its cell centre.
inline Eigen::Matrix4f world(int k, float shift = 0.0f) {
  Eigen::Affine3f m = Eigen::Affine3f::Identity();
  const Eigen::Vector2f c = cellCentre(k, shift);
  m.translate(Eigen::Vector3f(c.x(), c.y(), 0.0f));
  m.scale(Eigen::Vector3f(kHalf, kHalf, 1.0f));
  return m.matrix();
}
/// Camera 2 units back along +z, looking down -z; moves with the frame (the uniform buffer changes).
inline Eigen::Matrix4f view(uint64_t frame) {
  Eigen::Matrix4f v = Eigen::Matrix4f::Identity();
  v(2, 3) = -2.0f - 0.25f * static_cast<float>(frame % 4);
  return v;
}
/// Orthographic: x, y unchanged, z from -0.1 (near) to -10 (far) onto -1..1.
inline Eigen::Matrix4f projection() {
  const float n = 0.1f, f = 10.0f;
  Eigen::Matrix4f p = Eigen::Matrix4f::Identity();
  p(2, 2) = -2.0f / (f - n);
  p(2, 3) = -(f + n) / (f - n);
  return p;
}

}  // namespace stress_scene
}  // namespace viper
