// Object-space mesh extraction from shadow copies of a draw's vertex and index buffers.
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace viper {
namespace capture {

/// Where a draw's positions live in its vertex buffer (glVertexAttribPointer arguments).
struct PositionLayout {
  int size = 3;          ///< components (2, 3 or 4; z = 0 for 2)
  unsigned type = 0;     ///< GL type; only GL_FLOAT is extracted
  size_t stride = 0;     ///< bytes between vertices (0 = tightly packed)
  size_t offset = 0;     ///< byte offset of vertex 0
};

/// A draw's indices: null `data` for non-indexed draws.
struct DrawRange {
  unsigned mode = 4;         ///< GL primitive mode
  const uint8_t* index_data = nullptr;
  size_t index_bytes = 0;    ///< size of the index buffer
  unsigned index_type = 0;   ///< GL_UNSIGNED_BYTE/SHORT/INT
  size_t index_offset = 0;   ///< byte offset of the first index
  size_t count = 0;          ///< vertices (or indices) drawn
  long first = 0;            ///< first vertex of non-indexed draws
  long base_vertex = 0;      ///< added to every index
};

/// Result of extractMesh(): the mesh covers the buffer's vertex range [first_vertex, first_vertex + vertex_count).
struct ExtractedMesh {
  MeshRecord mesh;
  uint32_t first_vertex = 0;
  uint32_t vertex_count = 0;
};

/// Number of primitives `count` vertices form in `mode` (0 for unknown modes).
uint32_t primitiveCount(unsigned mode, size_t count);

/// Extracts positions of the vertex range a GL_TRIANGLES draw uses and its triangles (indices
/// relative to the range start), and sets mesh.key = contentKey(positions bytes + index bytes).
/// Returns false (and leaves `out` unspecified) for other modes, non-float positions, or ranges
/// that reach outside the given buffers.
bool extractMesh(const std::vector<uint8_t>& vertex_buffer, const PositionLayout& layout, const DrawRange& range,
                 ExtractedMesh& out);
/// The same from `vertex_bytes` bytes at `vertices` (a program's own memory, for client-side
/// vertex arrays: SIZE_MAX when only the draw itself bounds what may be read).
bool extractMesh(const uint8_t* vertices, size_t vertex_bytes, const PositionLayout& layout, const DrawRange& range,
                 ExtractedMesh& out);

}  // namespace capture
}  // namespace viper
