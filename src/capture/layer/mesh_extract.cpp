#include "mesh_extract.h"

#include "viper/capture/content_key.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cstring>
#include <limits>

namespace viper {
namespace capture {

uint32_t primitiveCount(unsigned mode, size_t count) {
  switch (mode) {
    case GL_POINTS: return static_cast<uint32_t>(count);
    case GL_LINES: return static_cast<uint32_t>(count / 2);
    case GL_LINE_STRIP: return count >= 2 ? static_cast<uint32_t>(count - 1) : 0;
    case GL_LINE_LOOP: return count >= 2 ? static_cast<uint32_t>(count) : 0;
    case GL_TRIANGLES: return static_cast<uint32_t>(count / 3);
    case GL_TRIANGLE_STRIP:
    case GL_TRIANGLE_FAN: return count >= 3 ? static_cast<uint32_t>(count - 2) : 0;
    default: return 0;
  }
}

namespace {

bool readIndex(const DrawRange& r, size_t i, long& out) {
  const size_t width = r.index_type == GL_UNSIGNED_BYTE ? 1 : r.index_type == GL_UNSIGNED_SHORT ? 2 : 4;
  const size_t at = r.index_offset + i * width;
  if (at + width > r.index_bytes) return false;
  const uint8_t* p = r.index_data + at;
  if (width == 1) out = *p;
  else if (width == 2) { uint16_t v; std::memcpy(&v, p, 2); out = v; }
  else { uint32_t v; std::memcpy(&v, p, 4); out = static_cast<long>(v); }
  out += r.base_vertex;
  return out >= 0;
}

}  // namespace

bool extractMesh(const std::vector<uint8_t>& vb, const PositionLayout& layout, const DrawRange& range,
                 ExtractedMesh& out) {
  return extractMesh(vb.data(), vb.size(), layout, range, out);
}

bool extractMesh(const uint8_t* vb, size_t vb_size, const PositionLayout& layout, const DrawRange& range,
                 ExtractedMesh& out) {
  if (range.mode != GL_TRIANGLES || layout.type != GL_FLOAT || layout.size < 2 || layout.size > 4) return false;
  const size_t triangles = range.count / 3;
  if (triangles == 0) return false;
  const size_t n = triangles * 3;

  std::vector<long> vertex(n);
  if (range.index_data) {
    if (range.index_type != GL_UNSIGNED_BYTE && range.index_type != GL_UNSIGNED_SHORT &&
        range.index_type != GL_UNSIGNED_INT)
      return false;
    for (size_t i = 0; i < n; ++i) {
      if (!readIndex(range, i, vertex[i])) return false;
    }
  } else {
    if (range.first < 0) return false;
    for (size_t i = 0; i < n; ++i) vertex[i] = range.first + static_cast<long>(i);
  }
  const long lo = *std::min_element(vertex.begin(), vertex.end());
  const long hi = *std::max_element(vertex.begin(), vertex.end());
  const size_t stride = layout.stride ? layout.stride : layout.size * sizeof(float);
  const size_t last_end = layout.offset + static_cast<size_t>(hi) * stride + layout.size * sizeof(float);
  if (!vb || last_end > vb_size || hi - lo >= static_cast<long>(std::numeric_limits<uint32_t>::max())) return false;

  const size_t count = static_cast<size_t>(hi - lo + 1);
  out.first_vertex = static_cast<uint32_t>(lo);
  out.vertex_count = static_cast<uint32_t>(count);
  out.mesh.positions_xyz.assign(count * 3, 0.0f);
  for (size_t v = 0; v < count; ++v) {
    const uint8_t* p = vb + layout.offset + (static_cast<size_t>(lo) + v) * stride;
    std::memcpy(&out.mesh.positions_xyz[v * 3], p, std::min(layout.size, 3) * sizeof(float));
  }
  out.mesh.indices.resize(n);
  for (size_t i = 0; i < n; ++i) out.mesh.indices[i] = static_cast<uint32_t>(vertex[i] - lo);

  std::string bytes(reinterpret_cast<const char*>(out.mesh.positions_xyz.data()),
                    out.mesh.positions_xyz.size() * sizeof(float));
  bytes.append(reinterpret_cast<const char*>(out.mesh.indices.data()), out.mesh.indices.size() * sizeof(uint32_t));
  out.mesh.key = contentKey(bytes);
  return true;
}

}  // namespace capture
}  // namespace viper
