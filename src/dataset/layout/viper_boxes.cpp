#include "viper/dataset/viper_boxes.h"

#include "viper_csv.h"

namespace viper::dataset {

std::string formatViperBoxRow(const ViperBoxRow& row) {
  std::string line = std::to_string(row.class_id) + "," + std::to_string(row.instance_id);
  line.reserve(300);
  for (double v : row.box_2d) line += ',', csv::appendNumber(line, v);
  for (double v : row.box_3d) line += ',', csv::appendNumber(line, v);
  for (double v : row.model_to_camera) line += ',', csv::appendNumber(line, v);
  return line;
}

void writeViperBoxesCsv(const std::string& path, const std::vector<ViperBoxRow>& rows, FileDigests* digests) {
  std::string text;
  text.reserve(rows.size() * 300);
  for (const ViperBoxRow& r : rows) text += formatViperBoxRow(r) + "\n";
  csv::writeTextFile(path, text, digests);
}

std::vector<ViperBoxRow> readViperBoxesCsv(const std::string& path, std::vector<std::string>& problems) {
  std::vector<ViperBoxRow> rows;
  csv::forEachRow(path, [&](size_t line, const std::vector<std::string>& f) {
    auto bad = [&](const std::string& what) {
      problems.push_back(path + ":" + std::to_string(line) + ": " + what + "; line skipped");
    };
    if (f.size() != 28) {
      bad("has " + std::to_string(f.size()) +
          " values, expected 28 (class id, instance id, 2D box 4, 3D box 6, model-to-camera matrix 16)");
      return;
    }
    ViperBoxRow row;
    uint64_t class_id = 0, instance_id = 0;
    if (!csv::parseCount(f[0], class_id) || class_id > 255) {
      bad("class id '" + f[0] + "' is not an integer in 0..255");
      return;
    }
    if (!csv::parseCount(f[1], instance_id) || instance_id > 0x7fffffffu) {
      bad("instance id '" + f[1] + "' is not a non-negative 32-bit integer");
      return;
    }
    row.class_id = static_cast<int>(class_id);
    row.instance_id = static_cast<int64_t>(instance_id);
    std::string what = csv::parseValues(f, 2, 4, row.box_2d.data());
    if (what.empty()) what = csv::parseValues(f, 6, 6, row.box_3d.data());
    if (what.empty()) what = csv::parseValues(f, 12, 16, row.model_to_camera.data());
    if (!what.empty()) {
      bad(what);
      return;
    }
    rows.push_back(row);
  });
  return rows;
}

}  // namespace viper::dataset
