// Named meshes of the world with the VIPER class each one belongs to (the source of --list-meshes
// and of the oracle's mesh names).
#pragma once

#include "mesh_data.h"

#include <map>
#include <string>
#include <vector>

namespace viper {
namespace world {

/// One named mesh. class_id -1 marks a mesh shared by several classes (wheels, lights).
struct MeshEntry {
  std::string name;
  int class_id = -1;
  MeshData data;
  Vec3 center;        ///< object-space bounding sphere centre
  float radius = 0;   ///< object-space bounding sphere radius (m)
};

/// Append-only store of named meshes; indices stay valid.
class MeshLibrary {
 public:
  /// Adds a mesh; throws std::logic_error if the name is taken. Returns its index.
  int add(const std::string& name, int class_id, MeshData data);
  /// Index of a mesh by name; throws std::out_of_range naming it if absent.
  int find(const std::string& name) const;
  const MeshEntry& at(int index) const { return entries_.at(index); }
  int size() const { return static_cast<int>(entries_.size()); }

 private:
  std::vector<MeshEntry> entries_;
  std::map<std::string, int> by_name_;
};

}  // namespace world
}  // namespace viper
