// The VIPER class table (ids 0-31, names, colors, which classes are scored).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// One row of config/viper_classes.csv.
struct ClassInfo {
  int id = 0;
  std::string name;
  std::array<uint8_t, 3> rgb{{0, 0, 0}};
  bool class_eval = false;     ///< scored in semantic segmentation
  int train_id = 255;          ///< 255 = not trained on
  bool instance_eval = false;  ///< scored in instance segmentation
};

/// The class table; ids index `classes` directly.
class ClassTable {
 public:
  /// Reads the CSV (header `id,classname,red,green,blue,class_eval,trainid,instance_eval`).
  /// Throws std::runtime_error naming the file and line for a missing file, bad header, bad
  /// value, or ids that are not 0..n-1 in order.
  static ClassTable load(const std::string& csv_path);

  const std::vector<ClassInfo>& classes() const { return classes_; }
  size_t size() const { return classes_.size(); }
  /// Throws std::out_of_range for an unknown id.
  const ClassInfo& at(int id) const { return classes_.at(static_cast<size_t>(id)); }
  /// Id of the class called `name`, or -1.
  int idOf(const std::string& name) const;
  /// Per id: whether the class is scored in semantic / instance segmentation.
  std::vector<bool> semanticEvalMask() const;
  std::vector<bool> instanceEvalMask() const;

 private:
  std::vector<ClassInfo> classes_;
};

}  // namespace viper
