// The resource label table: the once-per-asset annotation (resource content key -> VIPER class id)
// that semantic labels come from. Stored as YAML:
//
//   meshes:   {"8f3a0c1d22e4b7a9": 24, ...}   # mesh content key (16 hex digits) -> class id
//   textures: {"...": 9}
//   programs: {"...": 2}
//
// A draw's label is its mesh's, else its first labelled texture's, else its program's, else 0.
#pragma once

#include "viper/capture/capture_frame.h"

#include <cstdint>
#include <string>
#include <unordered_map>

namespace viper {

/// Resource key -> class id, for the three kinds of resource a draw names.
class LabelTable {
 public:
  /// Reads a label table. Throws std::runtime_error naming the file (and the entry) for a missing
  /// file, bad YAML, a key that is not 16 hex digits, or a class id outside 0..255.
  static LabelTable load(const std::string& yaml_path);
  /// Writes the table (keys sorted, so files diff well). Throws std::runtime_error on I/O failure.
  void save(const std::string& yaml_path) const;

  void setMesh(uint64_t key, uint8_t class_id) { meshes_[key] = class_id; }
  void setTexture(uint64_t key, uint8_t class_id) { textures_[key] = class_id; }
  void setProgram(uint64_t key, uint8_t class_id) { programs_[key] = class_id; }

  /// Class id of a draw from its resources (see file comment); 0 (unlabeled) if none is labelled.
  uint8_t classOf(const DrawRecord& draw) const;
  size_t size() const { return meshes_.size() + textures_.size() + programs_.size(); }

 private:
  std::unordered_map<uint64_t, uint8_t> meshes_, textures_, programs_;
};

/// 16 lower-case hex digits of a key, and back (throws std::invalid_argument on bad text).
std::string keyToHex(uint64_t key);
uint64_t keyFromHex(const std::string& hex);

}  // namespace viper
