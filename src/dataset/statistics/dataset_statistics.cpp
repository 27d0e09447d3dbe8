#include "viper/dataset/dataset_statistics.h"

#include "viper/dataset/viper_sequence.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <unordered_set>

namespace viper::dataset {
namespace {

// Names in a preferred order first, then the others by name.
std::vector<std::string> ordered(const std::vector<std::string>& names, const std::vector<std::string>& preferred) {
  std::vector<std::string> out;
  for (const std::string& p : preferred)
    if (std::find(names.begin(), names.end(), p) != names.end()) out.push_back(p);
  for (const std::string& n : names)
    if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  return out;
}

bool flag(const std::vector<ClassInfo>& classes, int id, bool ClassInfo::*member) {
  return id >= 0 && static_cast<size_t>(id) < classes.size() && classes[static_cast<size_t>(id)].*member;
}

// Class ids per pixel: the cls image, else the R channel of inst; empty if the frame has neither.
std::vector<uint8_t> classIds(const ViperFrame& frame) {
  if (frame.cls) return frame.cls->data;
  if (frame.inst) return viperInstanceClasses(*frame.inst);
  return {};
}

void countLabels(const ViperFrame& frame, const std::vector<ClassInfo>& classes, StatisticsCell& cell) {
  const std::vector<uint8_t> ids = classIds(frame);
  if (ids.empty()) return;
  std::array<uint64_t, 256> pixels{};
  for (uint8_t id : ids) ++pixels[id];
  int64_t present = 0;
  for (int id = 0; id < 256; ++id) {
    if (pixels[id] == 0) continue;
    cell.histograms[Statistic::kPixelsPerClass][id] += pixels[id];
    if (flag(classes, id, &ClassInfo::class_eval)) ++present;
  }
  ++cell.histograms[Statistic::kClassesPerImage][present];
  ++cell.images;
}

void countInstances(const ViperFrame& frame, const std::vector<ClassInfo>& classes, StatisticsCell& cell) {
  if (!frame.inst) return;
  // An instance is a (class, id) pair with id > 0; pixels of one come in runs, so only a change of
  // pair needs a look-up.
  std::unordered_set<uint32_t> seen;
  const std::vector<uint8_t>& rgb = frame.inst->data;
  uint32_t previous = 0;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
    const uint32_t key = (uint32_t{rgb[i]} << 16) | (uint32_t{rgb[i + 1]} << 8) | rgb[i + 2];
    if (key == previous || (key & 0xffff) == 0) continue;
    previous = key;
    if (flag(classes, static_cast<int>(key >> 16), &ClassInfo::instance_eval)) seen.insert(key);
  }
  for (uint32_t key : seen) ++cell.histograms[Statistic::kInstancesPerClass][key >> 16];
  ++cell.histograms[Statistic::kInstancesPerImage][static_cast<int64_t>(seen.size())];
}

void countVehicles(const ViperFrame& frame, const std::vector<int>& vehicles, double bin_m, StatisticsCell& cell) {
  if (!frame.boxes) return;
  for (const ViperBoxRow& row : *frame.boxes) {
    if (std::find(vehicles.begin(), vehicles.end(), row.class_id) == vehicles.end()) continue;
    if (row.box_2d[0] < 0) continue;  // no visible pixel
    // The box's centre, model -> camera coordinates.
    const std::array<double, 3> c{(row.box_3d[0] + row.box_3d[3]) / 2, (row.box_3d[1] + row.box_3d[4]) / 2,
                                  (row.box_3d[2] + row.box_3d[5]) / 2};
    double squared = 0.0;
    for (int r = 0; r < 3; ++r) {
      const double* m = &row.model_to_camera[4 * r];
      const double v = m[0] * c[0] + m[1] * c[1] + m[2] * c[2] + m[3];
      squared += v * v;
    }
    ++cell.histograms[Statistic::kVehiclesByDistance][static_cast<int64_t>(std::floor(std::sqrt(squared) / bin_m))];
  }
}

}  // namespace

uint64_t histogramTotal(const Histogram& h) {
  uint64_t n = 0;
  for (const auto& [bin, count] : h) n += count;
  return n;
}

const std::vector<Statistic>& allStatistics() {
  static const std::vector<Statistic> all = {Statistic::kClassesPerImage, Statistic::kInstancesPerImage,
                                             Statistic::kInstancesPerClass, Statistic::kVehiclesByDistance,
                                             Statistic::kPixelsPerClass};
  return all;
}

const char* statisticName(Statistic s) {
  switch (s) {
    case Statistic::kClassesPerImage: return "classes_per_image";
    case Statistic::kInstancesPerImage: return "instances_per_image";
    case Statistic::kInstancesPerClass: return "instances_per_class";
    case Statistic::kVehiclesByDistance: return "vehicles_by_distance";
    case Statistic::kPixelsPerClass: return "pixels_per_class";
  }
  return "?";
}

std::string statisticTitle(Statistic s) {
  std::string title = statisticName(s);
  std::replace(title.begin(), title.end(), '_', ' ');
  return title;
}

bool binsAreClasses(Statistic s) { return s == Statistic::kInstancesPerClass || s == Statistic::kPixelsPerClass; }

Histogram DatasetStatistics::pooled(Statistic statistic,
                                    const std::function<bool(const std::string&, const std::string&)>& take) const {
  Histogram sum;
  for (const auto& [key, cell] : cells) {
    if (!take(key.first, key.second)) continue;
    const auto h = cell.histograms.find(statistic);
    if (h == cell.histograms.end()) continue;
    for (const auto& [bin, count] : h->second) sum[bin] += count;
  }
  return sum;
}

std::vector<std::string> DatasetStatistics::splits() const {
  std::vector<std::string> names;
  for (const auto& [key, cell] : cells)
    if (std::find(names.begin(), names.end(), key.first) == names.end()) names.push_back(key.first);
  return ordered(names, {"train", "val", "test"});
}

std::vector<std::string> DatasetStatistics::conditions() const {
  std::vector<std::string> names;
  for (const auto& [key, cell] : cells)
    if (std::find(names.begin(), names.end(), key.second) == names.end()) names.push_back(key.second);
  std::sort(names.begin(), names.end());
  return ordered(names, {"day", "sunset", "rain", "snow", "night"});
}

DatasetStatistics computeDatasetStatistics(const std::string& root, const std::vector<StatisticsSequence>& sequences,
                                           const ClassTable& classes, const StatisticsOptions& options,
                                           const StatisticsProgress& progress) {
  if (!(options.distance_bin_m > 0.0))
    throw std::invalid_argument("distance bin must be > 0 m, not " + std::to_string(options.distance_bin_m));
  DatasetStatistics stats;
  stats.classes = classes.classes();
  stats.distance_bin_m = options.distance_bin_m;
  for (const std::string& name : options.vehicle_classes)
    if (classes.idOf(name) >= 0) stats.vehicle_class_ids.push_back(classes.idOf(name));
  const std::set<ViperModality> wanted = {ViperModality::kCls, ViperModality::kInst, ViperModality::kBb};
  for (size_t i = 0; i < sequences.size(); ++i) {
    const StatisticsSequence& q = sequences[i];
    if (progress) progress(i, sequences.size(), q);
    const ViperSequenceFiles files = scanViperSequence(root, q.split, q.seq);
    if (!files.has(ViperModality::kCls) && !files.has(ViperModality::kInst) && !files.has(ViperModality::kBb))
      throw std::runtime_error((std::filesystem::path(root) / q.split).string() + ": sequence " + q.seq +
                               " has no cls, inst or bb file");
    stats.problems.insert(stats.problems.end(), files.problems.begin(), files.problems.end());
    StatisticsCell& cell = stats.cells[{q.split, q.condition}];
    ++cell.sequences;
    for (uint64_t frame_number : viperSequenceFrames(files, {})) {
      const ViperFrame frame = readViperFrame(files, frame_number, {}, wanted, stats.problems);
      countLabels(frame, stats.classes, cell);
      countInstances(frame, stats.classes, cell);
      countVehicles(frame, stats.vehicle_class_ids, stats.distance_bin_m, cell);
    }
  }
  return stats;
}

std::vector<StatisticsSequence> planSequences(const DatasetPlan& plan) {
  std::vector<StatisticsSequence> out;
  for (const PlannedSequence& q : plan.sequences) out.push_back({q.split, q.id, q.condition});
  return out;
}

std::vector<StatisticsSequence> layoutSequences(const std::string& root) {
  std::vector<StatisticsSequence> out;
  for (const std::string& split : listViperSplits(root))
    for (const std::string& seq : listViperSequences(root, split)) out.push_back({split, seq, "unknown"});
  return out;
}

double jensenShannonBits(const Histogram& p, const Histogram& q) {
  const double np = static_cast<double>(histogramTotal(p)), nq = static_cast<double>(histogramTotal(q));
  if (np == 0.0 || nq == 0.0) return std::nan("");
  // JSD = (KL(P || M) + KL(Q || M)) / 2 with M = (P + Q) / 2, summed bin by bin rather than as
  // H(M) - (H(P) + H(Q)) / 2: equal shares give 0 exactly, and disjoint ones 1 up to the rounding of
  // the shares' sum.
  Histogram both = p;
  for (const auto& [bin, n] : q) both[bin] += 0;  // every bin of either
  double sum = 0.0;
  for (const auto& [bin, unused] : both) {
    const auto a = p.find(bin), b = q.find(bin);
    const double pp = a == p.end() ? 0.0 : static_cast<double>(a->second) / np;
    const double qq = b == q.end() ? 0.0 : static_cast<double>(b->second) / nq;
    if (pp > 0.0) sum += pp * std::log2(2.0 * pp / (pp + qq));
    if (qq > 0.0) sum += qq * std::log2(2.0 * qq / (pp + qq));
  }
  return std::clamp(sum / 2.0, 0.0, 1.0);  // rounding may stray just outside
}

}  // namespace viper::dataset
