#include "oracle_meshes.h"

#include <cmath>
#include <stdexcept>

namespace viper {
namespace world {

OracleMesh oracleMesh(const MeshEntry& entry) {
  const MeshData& d = entry.data;
  OracleMesh m;
  m.name = entry.name;
  m.positions_xyz = d.positions;
  m.indices = d.indices;
  if (d.skinned()) {
    // The shader reads ids as floats and truncates (int(aBoneIds.x)); the world stores whole numbers.
    m.bone_ids.reserve(d.bone_ids.size());
    for (float id : d.bone_ids) {
      if (!(id >= 0.0f && id < 1024.0f) || id != std::floor(id))
        throw std::invalid_argument("mesh " + entry.name + ": bone id " + std::to_string(id) + " is not a whole number 0..1023");
      m.bone_ids.push_back(static_cast<uint32_t>(id));
    }
    m.bone_weights = d.bone_weights;
  }
  return m;
}

void writeNewMeshes(OracleWriter& writer, const MeshLibrary& meshes, const OracleFrame& frame) {
  for (const OracleDraw& d : frame.draws)
    if (!writer.hasMesh(d.mesh)) writer.writeMesh(oracleMesh(meshes.at(meshes.find(d.mesh))));
}

}  // namespace world
}  // namespace viper
