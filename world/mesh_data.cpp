#include "mesh_data.h"

#include <algorithm>
#include <cmath>

namespace viper {
namespace world {

namespace {
Vec3 transformDir(const Mat4& m, Vec3 d) {
  return normalize({m.at(0, 0) * d.x + m.at(0, 1) * d.y + m.at(0, 2) * d.z,
                    m.at(1, 0) * d.x + m.at(1, 1) * d.y + m.at(1, 2) * d.z,
                    m.at(2, 0) * d.x + m.at(2, 1) * d.y + m.at(2, 2) * d.z});
}
}  // namespace

uint32_t MeshData::addVertex(Vec3 p, Vec3 n, Vec3 c) {
  uint32_t index = static_cast<uint32_t>(vertexCount());
  positions.insert(positions.end(), {p.x, p.y, p.z});
  normals.insert(normals.end(), {n.x, n.y, n.z});
  colors.insert(colors.end(), {c.x, c.y, c.z});
  if (current_bone >= 0) {
    bone_ids.insert(bone_ids.end(), {float(current_bone), 0, 0, 0});
    bone_weights.insert(bone_weights.end(), {1, 0, 0, 0});
  }
  return index;
}

void MeshData::addQuad(Vec3 a, Vec3 b, Vec3 c, Vec3 d, Vec3 color) {
  Vec3 n = normalize(cross(b - a, c - a));
  uint32_t i0 = addVertex(a, n, color), i1 = addVertex(b, n, color), i2 = addVertex(c, n, color),
           i3 = addVertex(d, n, color);
  indices.insert(indices.end(), {i0, i1, i2, i0, i2, i3});
}

void MeshData::addBox(const Mat4& m, Vec3 h, Vec3 color) {
  // Six faces, counter-clockwise seen from outside.
  const Vec3 c[8] = {{-h.x, -h.y, -h.z}, {h.x, -h.y, -h.z}, {h.x, h.y, -h.z}, {-h.x, h.y, -h.z},
                     {-h.x, -h.y, h.z},  {h.x, -h.y, h.z},  {h.x, h.y, h.z},  {-h.x, h.y, h.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  for (const auto& f : faces)
    addQuad(transformPoint(m, c[f[0]]), transformPoint(m, c[f[1]]), transformPoint(m, c[f[2]]),
            transformPoint(m, c[f[3]]), color);
}

void MeshData::addCylinder(const Mat4& m, float radius, float height, int segments, Vec3 color,
                           float top_radius) {
  if (top_radius < 0) top_radius = radius;
  uint32_t base = static_cast<uint32_t>(vertexCount());
  for (int i = 0; i <= segments; ++i) {
    float a = 2.0f * kPi * float(i % segments) / float(segments);
    float ca = std::cos(a), sa = std::sin(a);
    Vec3 n = transformDir(m, {ca, sa, (radius - top_radius) / std::max(height, 1e-3f)});
    addVertex(transformPoint(m, {radius * ca, radius * sa, 0}), n, color);
    addVertex(transformPoint(m, {top_radius * ca, top_radius * sa, height}), n, color);
  }
  for (int i = 0; i < segments; ++i) {
    uint32_t a = base + 2 * i;
    indices.insert(indices.end(), {a, a + 2, a + 3, a, a + 3, a + 1});
  }
  // Caps as fans.
  for (int cap = 0; cap < 2; ++cap) {
    float z = cap ? height : 0.0f, r = cap ? top_radius : radius;
    if (r <= 0) continue;
    Vec3 n = transformDir(m, {0, 0, cap ? 1.0f : -1.0f});
    uint32_t center = addVertex(transformPoint(m, {0, 0, z}), n, color);
    for (int i = 0; i < segments; ++i) {
      float a = 2.0f * kPi * float(i) / float(segments);
      addVertex(transformPoint(m, {r * std::cos(a), r * std::sin(a), z}), n, color);
    }
    for (int i = 0; i < segments; ++i) {
      uint32_t a = center + 1 + i, b = center + 1 + (i + 1) % segments;
      if (cap) indices.insert(indices.end(), {center, a, b});
      else indices.insert(indices.end(), {center, b, a});
    }
  }
}

void MeshData::addSphere(const Mat4& m, Vec3 r, int segments, int rings, Vec3 color) {
  uint32_t base = static_cast<uint32_t>(vertexCount());
  for (int j = 0; j <= rings; ++j) {
    float v = kPi * float(j) / float(rings) - 0.5f * kPi;
    for (int i = 0; i <= segments; ++i) {
      float u = 2.0f * kPi * float(i % segments) / float(segments);
      Vec3 unit{std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
      addVertex(transformPoint(m, {unit.x * r.x, unit.y * r.y, unit.z * r.z}),
                transformDir(m, {unit.x / r.x, unit.y / r.y, unit.z / r.z}), color);
    }
  }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      uint32_t a = base + j * (segments + 1) + i, b = a + segments + 1;
      indices.insert(indices.end(), {a, a + 1, b + 1, a, b + 1, b});
    }
}

void MeshData::addExtrusion(const Mat4& m, const std::vector<Vec3>& profile, float hw,
                            Vec3 color) {
  const size_t n = profile.size();
  // Side walls between consecutive profile points.
  for (size_t i = 0; i < n; ++i) {
    Vec3 a = profile[i], b = profile[(i + 1) % n];
    addQuad(transformPoint(m, {a.x, hw, a.z}), transformPoint(m, {b.x, hw, b.z}),
            transformPoint(m, {b.x, -hw, b.z}), transformPoint(m, {a.x, -hw, a.z}), color);
  }
  // Two caps as fans (the profile is convex).
  for (int side = 0; side < 2; ++side) {
    float y = side ? hw : -hw;
    Vec3 nrm = transformDir(m, {0, side ? 1.0f : -1.0f, 0});
    uint32_t first = static_cast<uint32_t>(vertexCount());
    for (const Vec3& p : profile) addVertex(transformPoint(m, {p.x, y, p.z}), nrm, color);
    for (uint32_t i = 1; i + 1 < n; ++i) {
      if (side) indices.insert(indices.end(), {first, first + i + 1, first + i});
      else indices.insert(indices.end(), {first, first + i, first + i + 1});
    }
  }
}

void MeshData::append(const MeshData& o, const Mat4& m) {
  uint32_t base = static_cast<uint32_t>(vertexCount());
  for (size_t v = 0; v < o.vertexCount(); ++v) {
    Vec3 p{o.positions[3 * v], o.positions[3 * v + 1], o.positions[3 * v + 2]};
    Vec3 n{o.normals[3 * v], o.normals[3 * v + 1], o.normals[3 * v + 2]};
    Vec3 c{o.colors[3 * v], o.colors[3 * v + 1], o.colors[3 * v + 2]};
    addVertex(transformPoint(m, p), transformDir(m, n), c);
  }
  for (uint32_t i : o.indices) indices.push_back(base + i);
}

void MeshData::bounds(Vec3& center, float& radius) const {
  if (positions.empty()) {
    center = {};
    radius = 0;
    return;
  }
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (size_t v = 0; v < vertexCount(); ++v) {
    lo = {std::min(lo.x, positions[3 * v]), std::min(lo.y, positions[3 * v + 1]),
          std::min(lo.z, positions[3 * v + 2])};
    hi = {std::max(hi.x, positions[3 * v]), std::max(hi.y, positions[3 * v + 1]),
          std::max(hi.z, positions[3 * v + 2])};
  }
  center = (lo + hi) * 0.5f;
  radius = length(hi - lo) * 0.5f;
}

}  // namespace world
}  // namespace viper
