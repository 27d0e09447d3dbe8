#include "viper/ground_truth/label_table.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>
#include <vector>

namespace viper {

std::string keyToHex(uint64_t key) {
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(key));
  return buf;
}

uint64_t keyFromHex(const std::string& hex) {
  if (hex.size() != 16 || hex.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw std::invalid_argument("'" + hex + "' is not a resource key (16 hex digits)");
  return std::stoull(hex, nullptr, 16);
}

namespace {

void readSection(const YAML::Node& root, const char* name, const std::string& path,
                 std::unordered_map<uint64_t, uint8_t>& out) {
  const YAML::Node section = root[name];
  if (!section || section.IsNull()) return;
  if (!section.IsMap()) throw std::runtime_error(path + ": '" + name + "' must be a map of key: class id");
  for (const auto& entry : section) {
    const std::string key_text = entry.first.as<std::string>();
    int class_id = -1;
    try {
      class_id = entry.second.as<int>();
    } catch (const YAML::Exception&) {
    }
    if (class_id < 0 || class_id > 255)
      throw std::runtime_error(path + ": " + name + "." + key_text + ": class id must be an integer in 0..255");
    try {
      out[keyFromHex(key_text)] = static_cast<uint8_t>(class_id);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ": " + name + ": " + e.what());
    }
  }
}

void writeSection(std::ostream& out, const char* name, const std::unordered_map<uint64_t, uint8_t>& m) {
  std::map<uint64_t, uint8_t> sorted(m.begin(), m.end());
  out << name << ":" << (sorted.empty() ? " {}\n" : "\n");
  for (const auto& kv : sorted) out << "  \"" << keyToHex(kv.first) << "\": " << static_cast<int>(kv.second) << "\n";
}

}  // namespace

LabelTable LabelTable::load(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(path + ": cannot open label table");
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error(path + ": a label table is a map with meshes/textures/programs");
  LabelTable t;
  readSection(root, "meshes", path, t.meshes_);
  readSection(root, "textures", path, t.textures_);
  readSection(root, "programs", path, t.programs_);
  return t;
}

void LabelTable::save(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write label table");
  out << "# viper resource label table: resource content key -> VIPER class id\n";
  writeSection(out, "meshes", meshes_);
  writeSection(out, "textures", textures_);
  writeSection(out, "programs", programs_);
  if (!out) throw std::runtime_error(path + ": write failed");
}

uint8_t LabelTable::classOf(const DrawRecord& d) const {
  if (auto it = meshes_.find(d.mesh_key); it != meshes_.end()) return it->second;
  for (uint64_t t : d.texture_keys)
    if (auto it = textures_.find(t); it != textures_.end()) return it->second;
  if (auto it = programs_.find(d.program_key); it != programs_.end()) return it->second;
  return 0;
}

}  // namespace viper
