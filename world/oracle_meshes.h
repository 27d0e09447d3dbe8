// The oracle's mesh records of the world: the object-space geometry of every mesh a frame draws,
// taken from the very buffers the renderer uploads (docs/oracle_format.md, version 2).
#pragma once

#include "mesh_library.h"

#include "viper/ground_truth/oracle.h"

namespace viper {
namespace world {

/// The oracle record of a mesh: its name, the position buffer bound to aPos, the index buffer and,
/// for skinned meshes, the bone ids and weights of locations 3/4. Throws std::invalid_argument if
/// a bone id is not a whole number in 0..1023.
OracleMesh oracleMesh(const MeshEntry& mesh);

/// Writes the record of every mesh `frame` draws that `writer` has not written yet (call before
/// writer.write(frame)). Throws std::out_of_range if a draw names a mesh the library lacks.
void writeNewMeshes(OracleWriter& writer, const MeshLibrary& meshes, const OracleFrame& frame);

}  // namespace world
}  // namespace viper
