// Minimal column-major 4x4 float matrix and 3-vector maths for the world (no dependencies, so the
// float results are the same on every run).
#pragma once

#include <cmath>

namespace viper {
namespace world {

/// A 3-vector (metres in the world frame unless said otherwise).
struct Vec3 {
  float x = 0, y = 0, z = 0;
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) {
  float l = length(a);
  return l > 0 ? a * (1.0f / l) : Vec3{0, 0, 1};
}

/// Column-major 4x4 matrix, as glUniformMatrix4fv(..., GL_FALSE, m) expects.
struct Mat4 {
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  float& at(int row, int col) { return m[col * 4 + row]; }
  float at(int row, int col) const { return m[col * 4 + row]; }
};

inline Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a.at(row, k) * b.at(k, c);
      r.at(row, c) = s;
    }
  return r;
}

inline Vec3 transformPoint(const Mat4& a, Vec3 p) {
  return {a.at(0, 0) * p.x + a.at(0, 1) * p.y + a.at(0, 2) * p.z + a.at(0, 3),
          a.at(1, 0) * p.x + a.at(1, 1) * p.y + a.at(1, 2) * p.z + a.at(1, 3),
          a.at(2, 0) * p.x + a.at(2, 1) * p.y + a.at(2, 2) * p.z + a.at(2, 3)};
}

inline Mat4 translation(Vec3 t) {
  Mat4 r;
  r.at(0, 3) = t.x;
  r.at(1, 3) = t.y;
  r.at(2, 3) = t.z;
  return r;
}

inline Mat4 scaling(Vec3 s) {
  Mat4 r;
  r.at(0, 0) = s.x;
  r.at(1, 1) = s.y;
  r.at(2, 2) = s.z;
  return r;
}

/// Rotation about an axis through the origin (right-handed, radians).
inline Mat4 rotationX(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.at(1, 1) = c; r.at(1, 2) = -s; r.at(2, 1) = s; r.at(2, 2) = c;
  return r;
}
inline Mat4 rotationY(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.at(0, 0) = c; r.at(0, 2) = s; r.at(2, 0) = -s; r.at(2, 2) = c;
  return r;
}
inline Mat4 rotationZ(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.at(0, 0) = c; r.at(0, 1) = -s; r.at(1, 0) = s; r.at(1, 1) = c;
  return r;
}

/// Object -> world pose: position, heading about Z, then optional pitch/roll (radians).
inline Mat4 pose(Vec3 p, float yaw, float roll = 0.0f, float pitch = 0.0f) {
  return translation(p) * rotationZ(yaw) * rotationY(pitch) * rotationX(roll);
}

/// Inverse of a rigid transform (rotation + translation only).
inline Mat4 rigidInverse(const Mat4& a) {
  Mat4 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.at(i, j) = a.at(j, i);
  for (int i = 0; i < 3; ++i)
    r.at(i, 3) = -(r.at(i, 0) * a.at(0, 3) + r.at(i, 1) * a.at(1, 3) + r.at(i, 2) * a.at(2, 3));
  return r;
}

/// OpenGL perspective projection (vertical field of view in radians).
inline Mat4 perspective(float fovy, float aspect, float near_m, float far_m) {
  Mat4 r;
  float f = 1.0f / std::tan(fovy * 0.5f);
  r.at(0, 0) = f / aspect;
  r.at(1, 1) = f;
  r.at(2, 2) = (far_m + near_m) / (near_m - far_m);
  r.at(2, 3) = 2.0f * far_m * near_m / (near_m - far_m);
  r.at(3, 2) = -1.0f;
  r.at(3, 3) = 0.0f;
  return r;
}

constexpr float kPi = 3.14159265358979f;

}  // namespace world
}  // namespace viper
