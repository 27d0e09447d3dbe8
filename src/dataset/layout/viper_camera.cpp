#include "viper/dataset/viper_camera.h"

#include "viper/dataset/viper_layout.h"
#include "viper_csv.h"

#include <filesystem>
#include <stdexcept>

namespace viper::dataset {

RowMajor4 identity4() {
  RowMajor4 m{};
  m[0] = m[5] = m[10] = m[15] = 1.0;
  return m;
}

std::string viperCameraPath(const std::string& root, const std::string& split, const std::string& seq) {
  // viperFramePath checks the parts; the camera file sits one folder up, named after the sequence.
  const std::filesystem::path frame = viperFramePath(root, split, "camera", seq, 0, "csv");
  return (frame.parent_path().parent_path() / (seq + ".csv")).string();
}

std::string formatViperCameraRow(const ViperCameraRow& row) {
  std::string line = std::to_string(row.frame);
  line.reserve(400);
  for (double v : row.projection) line += ',', csv::appendNumber(line, v);
  for (double v : row.view) line += ',', csv::appendNumber(line, v);
  return line;
}

void writeViperCameraCsv(const std::string& path, const std::vector<ViperCameraRow>& rows) {
  std::string text;
  text.reserve(rows.size() * 400);
  for (const ViperCameraRow& r : rows) text += formatViperCameraRow(r) + "\n";
  csv::writeTextFile(path, text);
}

std::map<uint64_t, ViperCameraRow> readViperCameraCsv(const std::string& path, std::vector<std::string>& problems) {
  std::map<uint64_t, ViperCameraRow> rows;
  std::map<uint64_t, size_t> line_of;
  csv::forEachRow(path, [&](size_t line, const std::vector<std::string>& f) {
    auto bad = [&](const std::string& what) {
      problems.push_back(path + ":" + std::to_string(line) + ": " + what + "; line skipped");
    };
    if (f.size() != 33) {
      bad("has " + std::to_string(f.size()) + " values, expected 33 (frame id, projection 4x4, view 4x4)");
      return;
    }
    ViperCameraRow row;
    if (!csv::parseCount(f[0], row.frame)) {
      bad("frame id '" + f[0] + "' is not a non-negative integer");
      return;
    }
    std::string what = csv::parseValues(f, 1, 16, row.projection.data());
    if (what.empty()) what = csv::parseValues(f, 17, 16, row.view.data());
    if (!what.empty()) {
      bad(what);
      return;
    }
    const auto seen = line_of.find(row.frame);
    if (seen != line_of.end()) {
      bad("frame " + std::to_string(row.frame) + " was already given on line " + std::to_string(seen->second));
      return;
    }
    line_of[row.frame] = line;
    rows[row.frame] = row;
  });
  return rows;
}

}  // namespace viper::dataset
