// The evaluate testers' own arithmetic, independent of the core: expected flow, semantic and
// odometry scores, and readers of the report files the evaluate node writes.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace evaluate_expect {

// Expected flow scores, accumulated here independently of the core.
struct FlowExpect {
  uint64_t n = 0, outliers = 0;
  double epe = 0.0, wauc = 0.0;
  void add(double e, double gt_norm) {
    ++n;
    epe += e;
    if (e < 5.0) wauc += (1.0 - e / 5.0) * (1.0 - e / 5.0);
    if (e > 3.0 && e > 0.05 * gt_norm) ++outliers;
  }
  void merge(const FlowExpect& o) { n += o.n, outliers += o.outliers, epe += o.epe, wauc += o.wauc; }
  double epeMean() const { return epe / n; }
  double waucPercent() const { return 100.0 * wauc / n; }
  double outlierPercent() const { return 100.0 * outliers / n; }
};

// Expected semantic scores: confusion over ground-truth pixels of scored classes.
struct SemanticExpect {
  std::vector<uint64_t> tp = std::vector<uint64_t>(256), fp = std::vector<uint64_t>(256),
                        fn = std::vector<uint64_t>(256);
  void merge(const SemanticExpect& o) {
    for (int c = 0; c < 256; ++c) tp[c] += o.tp[c], fp[c] += o.fp[c], fn[c] += o.fn[c];
  }
  // Over the scored classes with any TP, FP or FN (cityscapesScripts).
  double meanIou(const std::vector<bool>& scored) const {
    double sum = 0;
    int k = 0;
    for (size_t c = 0; c < scored.size(); ++c)
      if (scored[c] && tp[c] + fp[c] + fn[c] > 0) sum += static_cast<double>(tp[c]) / (tp[c] + fp[c] + fn[c]), ++k;
    return 100.0 * sum / k;
  }
};

// The row of `condition` (first cell) of a CSV file with a header, by column; empty if none.
inline std::map<std::string, std::string> csvRow(const std::string& path, const std::string& condition) {
  std::ifstream f(path);
  std::string header, line;
  std::getline(f, header);
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
    if (!s.empty() && s.back() == ',') out.push_back("");
    return out;
  };
  const auto keys = split(header);
  while (std::getline(f, line)) {
    const auto cells = split(line);
    if (cells.empty() || cells[0] != condition) continue;
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < keys.size() && i < cells.size(); ++i) row[keys[i]] = cells[i];
    return row;
  }
  return {};
}

// A cell as a number; NaN if missing or empty.
inline double number(const std::map<std::string, std::string>& row, const std::string& key) {
  const auto it = row.find(key);
  if (it == row.end() || it->second.empty()) return NAN;
  return std::stod(it->second);
}

// Frames counted in the "all" block of the running scores, "" key -> -1 if absent.
inline long framesIn(const std::string& yaml, const std::string& key) {
  const std::string field = key == "odometry" ? "poses" : "frames";
  const std::string needle = "\n  " + key + ": {" + field + ": ";
  const size_t at = ("\n" + yaml).find(needle);
  if (at == std::string::npos) return -1;
  return std::stol(yaml.substr(at + needle.size() - 1));
}

// KITTI segments of one trajectory whose estimate is stretched by `stretch` about its first pose: the
// error of a segment is (stretch - 1) times the straight distance between its ends, divided by its
// nominal length. Appends each segment's translation ratio.
inline void stretchedSegments(const std::vector<Eigen::Isometry3d>& gt, const std::vector<double>& lengths,
                              size_t step, double stretch, std::vector<double>& translation_ratios) {
  std::vector<double> dist(gt.size(), 0.0);
  for (size_t i = 1; i < gt.size(); ++i) dist[i] = dist[i - 1] + (gt[i].translation() - gt[i - 1].translation()).norm();
  for (size_t first = 0; first < gt.size(); first += step)
    for (double len : lengths)
      for (size_t last = first; last < gt.size(); ++last)
        if (dist[last] > dist[first] + len) {
          translation_ratios.push_back((stretch - 1.0) * (gt[last].translation() - gt[first].translation()).norm() / len);
          break;
        }
}

}  // namespace evaluate_expect
