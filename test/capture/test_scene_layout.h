// The capture test program's scene, shared by the program and the tests that check its capture:
// geometry, matrices and skinning as functions of the frame number.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace viper {
namespace test_scene {

/// Draw order of one frame (indices into the frame's draw list).
enum DrawIndex : uint32_t { kQuad = 0, kTriangle = 1, kGlass = 2, kSkinned = 3, kDrawCount = 4 };

inline Eigen::Matrix4f translation(float x, float y, float z) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m(0, 3) = x, m(1, 3) = y, m(2, 3) = z;
  return m;
}

/// Orthographic projection over x in [-2, 2], y in [-1.5, 1.5], near 0.1, far 10.
inline Eigen::Matrix4f projection() {
  const float l = -2, r = 2, b = -1.5f, t = 1.5f, n = 0.1f, f = 10;
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = 2 / (r - l), m(0, 3) = -(r + l) / (r - l);
  m(1, 1) = 2 / (t - b), m(1, 3) = -(t + b) / (t - b);
  m(2, 2) = -2 / (f - n), m(2, 3) = -(f + n) / (f - n);
  m(3, 3) = 1;
  return m;
}

inline Eigen::Matrix4f view() { return translation(0, 0, -5); }

/// World matrix of a draw in a frame.
inline Eigen::Matrix4f world(uint32_t draw, uint64_t frame) {
  switch (draw) {
    case kQuad: return translation(-1, 0, 0);
    case kTriangle: return translation(1, 0, -0.1f * static_cast<float>(frame % 10));
    case kGlass: return translation(0, 0, 0.5f);
    default: return translation(0, 0.9f, 0);
  }
}

/// Quad (draw 0): 4 vertices xyz, 6 indices; triangle 0 is the lower-right half.
inline std::vector<float> quadVertices() { return {-0.9f, -0.9f, 0, 0.9f, -0.9f, 0, 0.9f, 0.9f, 0, -0.9f, 0.9f, 0}; }
inline std::vector<uint16_t> quadIndices() { return {0, 1, 2, 0, 2, 3}; }
/// Triangle (draw 1): 3 vertices xyz, drawn with glDrawArrays.
inline std::vector<float> triangleVertices() { return {-0.9f, -0.9f, 0, 0.9f, -0.9f, 0, 0, 0.9f, 0}; }
/// Glass (draw 2): two triangles (6 vertices), alpha 0.4, no depth writes.
inline std::vector<float> glassVertices() {
  return {-1, -0.5f, 0, 1, -0.5f, 0, 1, 0.5f, 0, -1, -0.5f, 0, 1, 0.5f, 0, -1, 0.5f, 0};
}

/// Skinned strip (draw 3): interleaved x, y, z, weight; 3 unused vertices first (drawn with
/// base vertex 3), then 2 rows of 5 columns.
constexpr int kSkinPadding = 3;
inline std::vector<float> skinnedVertices() {
  std::vector<float> v(kSkinPadding * 4, 7.0f);
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 5; ++col) {
      const float x = -1.0f + 0.5f * col;
      v.insert(v.end(), {x, 0.4f * row, 0.0f, (x + 1.0f) / 2.0f});
    }
  return v;
}
inline std::vector<uint32_t> skinnedIndices() {
  std::vector<uint32_t> idx;
  for (uint32_t c = 0; c < 4; ++c) idx.insert(idx.end(), {c, c + 1, c + 6, c, c + 6, c + 5});
  return idx;
}
/// Bone matrices of the skinned strip: bone 0 fixed, bone 1 lifts with the frame number.
inline Eigen::Matrix4f bone(int index, uint64_t frame) {
  return index == 0 ? Eigen::Matrix4f::Identity() : translation(0, 0.05f + 0.02f * static_cast<float>(frame % 8), 0);
}
/// What the skinning vertex shader computes for a strip vertex (object space, after skinning).
inline Eigen::Vector4f skinned(const Eigen::Vector3f& p, float weight, uint64_t frame) {
  const Eigen::Vector4f h(p.x(), p.y(), p.z(), 1.0f);
  return (1.0f - weight) * (bone(0, frame) * h) + weight * (bone(1, frame) * h);
}

}  // namespace test_scene
}  // namespace viper
