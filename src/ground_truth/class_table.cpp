#include "viper/ground_truth/class_table.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace viper {
namespace {

int parseInt(const std::string& field, int lo, int hi, const std::string& where) {
  size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(field, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != field.size() || v < lo || v > hi)
    throw std::runtime_error(where + ": '" + field + "' is not an integer in [" + std::to_string(lo) +
                             ", " + std::to_string(hi) + "]");
  return v;
}

}  // namespace

ClassTable ClassTable::load(const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) throw std::runtime_error(csv_path + ": cannot open class table");
  std::string line;
  if (!std::getline(in, line) || line.rfind("id,classname,red,green,blue,class_eval", 0) != 0)
    throw std::runtime_error(csv_path + ":1: expected header 'id,classname,red,green,blue,class_eval,trainid,instance_eval'");
  ClassTable table;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    const std::string where = csv_path + ":" + std::to_string(line_no);
    if (f.size() != 8) throw std::runtime_error(where + ": expected 8 columns, got " + std::to_string(f.size()));
    ClassInfo c;
    c.id = parseInt(f[0], 0, 254, where);
    if (c.id != static_cast<int>(table.classes_.size()))
      throw std::runtime_error(where + ": class id " + f[0] + " out of order (expected " +
                               std::to_string(table.classes_.size()) + ")");
    c.name = f[1];
    for (int k = 0; k < 3; ++k) c.rgb[k] = static_cast<uint8_t>(parseInt(f[2 + k], 0, 255, where));
    c.class_eval = parseInt(f[5], 0, 1, where) == 1;
    c.train_id = parseInt(f[6], 0, 255, where);
    c.instance_eval = parseInt(f[7], 0, 1, where) == 1;
    table.classes_.push_back(c);
  }
  if (table.classes_.empty()) throw std::runtime_error(csv_path + ": no classes");
  return table;
}

int ClassTable::idOf(const std::string& name) const {
  for (const auto& c : classes_)
    if (c.name == name) return c.id;
  return -1;
}

std::vector<bool> ClassTable::semanticEvalMask() const {
  std::vector<bool> m;
  for (const auto& c : classes_) m.push_back(c.class_eval);
  return m;
}

std::vector<bool> ClassTable::instanceEvalMask() const {
  std::vector<bool> m;
  for (const auto& c : classes_) m.push_back(c.instance_eval);
  return m;
}

}  // namespace viper
