#include "mesh_library.h"

#include <stdexcept>

namespace viper {
namespace world {

int MeshLibrary::add(const std::string& name, int class_id, MeshData data) {
  if (by_name_.count(name)) throw std::logic_error("mesh name used twice: " + name);
  MeshEntry e;
  e.name = name;
  e.class_id = class_id;
  e.data = std::move(data);
  e.data.bounds(e.center, e.radius);
  entries_.push_back(std::move(e));
  by_name_[name] = size() - 1;
  return size() - 1;
}

int MeshLibrary::find(const std::string& name) const {
  auto it = by_name_.find(name);
  if (it == by_name_.end()) throw std::out_of_range("no mesh named " + name);
  return it->second;
}

}  // namespace world
}  // namespace viper
