#include "geometry.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace viper {
namespace scene {
namespace {

void addLitVertex(MeshData& m, const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
  m.vertices.insert(m.vertices.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()});
}

void addQuad(MeshData& m, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
}

// Uniform in [0, 1) from the raw 64-bit output, so the layout does not depend on the standard
// library's distribution implementation.
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

int floatsPerVertex(VertexLayout layout) {
  switch (layout) {
    case VertexLayout::kLit: return 6;
    case VertexLayout::kSkinned: return 14;
    case VertexLayout::kRain: return 4;
  }
  return 0;
}

MeshData makeGrid(const std::string& name, float half_x, float half_y, float z, int cells) {
  MeshData m{name, VertexLayout::kLit, {}, {}};
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      addLitVertex(m, {-half_x + 2 * half_x * i / cells, -half_y + 2 * half_y * j / cells, z}, Eigen::Vector3f::UnitZ());
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = j * (cells + 1) + i;
      addQuad(m, a, a + 1, a + cells + 2, a + cells + 1);
    }
  return m;
}

MeshData makeBox(const std::string& name, const Eigen::Vector3f& center, const Eigen::Vector3f& size) {
  MeshData m{name, VertexLayout::kLit, {}, {}};
  const Eigen::Vector3f h = size / 2;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      const Eigen::Vector3f u = Eigen::Vector3f::Unit((axis + 1) % 3) * static_cast<float>(sign);
      const Eigen::Vector3f v = Eigen::Vector3f::Unit((axis + 2) % 3);
      const uint32_t base = static_cast<uint32_t>(m.vertices.size() / 6);
      for (const auto& [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
        addLitVertex(m, center + (n + u * su + v * sv).cwiseProduct(h), n);
      addQuad(m, base, base + 1, base + 2, base + 3);
    }
  return m;
}

MeshData makeWheel(const std::string& name, const Eigen::Vector3f& center, float radius, float width, int sides) {
  MeshData m{name, VertexLayout::kLit, {}, {}};
  const float pi = static_cast<float>(M_PI);
  // Side: two rings of outward normals.
  for (int i = 0; i <= sides; ++i) {
    const float a = 2 * pi * i / sides;
    const Eigen::Vector3f radial(std::cos(a), 0, std::sin(a));
    for (float y : {-width / 2, width / 2}) addLitVertex(m, center + radius * radial + Eigen::Vector3f(0, y, 0), radial);
  }
  for (int i = 0; i < sides; ++i) addQuad(m, 2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
  // Caps: a centre vertex and a ring each.
  for (float sign : {-1.f, 1.f}) {
    const Eigen::Vector3f n(0, sign, 0);
    const uint32_t c = static_cast<uint32_t>(m.vertices.size() / 6);
    addLitVertex(m, center + n * (width / 2), n);
    for (int i = 0; i <= sides; ++i) {
      const float a = 2 * pi * i / sides;
      addLitVertex(m, center + Eigen::Vector3f(radius * std::cos(a), sign * width / 2, radius * std::sin(a)), n);
    }
    for (int i = 0; i < sides; ++i) m.indices.insert(m.indices.end(), {c, c + 1 + i, c + 2 + i});
  }
  return m;
}

MeshData makeSkinnedTube(const std::string& name, float radius, float height, int bones, float blend, int sides,
                         int rings) {
  MeshData m{name, VertexLayout::kSkinned, {}, {}};
  const float segment = height / bones;
  const float pi = static_cast<float>(M_PI);
  auto add = [&](const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
    // Bone of the segment, blended with the neighbour across the nearest joint.
    const int bone = std::min(bones - 1, static_cast<int>(p.z() / segment));
    int other = bone;
    float w_other = 0;
    const float below = p.z() - bone * segment, above = (bone + 1) * segment - p.z();
    if (bone > 0 && below < blend) {
      other = bone - 1;
      w_other = 0.5f * (1 - below / blend);
    } else if (bone < bones - 1 && above < blend) {
      other = bone + 1;
      w_other = 0.5f * (1 - above / blend);
    }
    m.vertices.insert(m.vertices.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), static_cast<float>(bone),
                                         static_cast<float>(other), 0.f, 0.f, 1 - w_other, w_other, 0.f, 0.f});
  };
  for (int r = 0; r <= rings; ++r)
    for (int i = 0; i <= sides; ++i) {
      const float a = 2 * pi * i / sides;
      add({radius * std::cos(a), radius * std::sin(a), height * r / rings}, {std::cos(a), std::sin(a), 0});
    }
  for (int r = 0; r < rings; ++r)
    for (int i = 0; i < sides; ++i) {
      const uint32_t a = r * (sides + 1) + i;
      addQuad(m, a, a + 1, a + sides + 2, a + sides + 1);
    }
  // Top cap (the head end), so the tube is closed where the camera looks down on it.
  const uint32_t c = static_cast<uint32_t>(m.vertices.size() / 14);
  add({0, 0, height}, Eigen::Vector3f::UnitZ());
  for (int i = 0; i <= sides; ++i) {
    const float a = 2 * pi * i / sides;
    add({radius * std::cos(a), radius * std::sin(a), height}, Eigen::Vector3f::UnitZ());
  }
  for (int i = 0; i < sides; ++i) m.indices.insert(m.indices.end(), {c, c + 1 + i, c + 2 + i});
  return m;
}

MeshData makeRainStreaks(const std::string& name, uint64_t seed, int count, const Eigen::Vector3f& box_min,
                         const Eigen::Vector3f& box_max, const Eigen::Vector3f& normal) {
  MeshData m{name, VertexLayout::kRain, {}, {}};
  std::mt19937_64 rng(seed);
  const Eigen::Vector3f side = Eigen::Vector3f::UnitZ().cross(normal).normalized() * 0.03f;
  const float length = 1.2f;
  for (int s = 0; s < count; ++s) {
    Eigen::Vector3f bottom;
    for (int k = 0; k < 3; ++k) bottom[k] = static_cast<float>(box_min[k] + unit(rng) * (box_max[k] - box_min[k]));
    const uint32_t base = static_cast<uint32_t>(m.vertices.size() / 4);
    // Three rows (bottom, middle, top) so alpha peaks mid-streak.
    const float alphas[3] = {0.05f, 0.6f, 0.05f};
    for (int row = 0; row < 3; ++row)
      for (float sign : {-1.f, 1.f}) {
        const Eigen::Vector3f p = bottom + side * sign + Eigen::Vector3f(0, 0, length * row / 2);
        m.vertices.insert(m.vertices.end(), {p.x(), p.y(), p.z(), alphas[row]});
      }
    addQuad(m, base, base + 1, base + 3, base + 2);
    addQuad(m, base + 2, base + 3, base + 5, base + 4);
  }
  return m;
}

}  // namespace scene
}  // namespace viper
