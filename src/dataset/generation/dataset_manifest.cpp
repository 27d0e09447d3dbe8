#include "viper/dataset/dataset_manifest.h"

#include "viper/dataset/sequence_marker.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

namespace viper::dataset {

MergeResult mergeDataset(const DatasetPlan& plan, const std::string& root) {
  namespace fs = std::filesystem;
  MergeResult result;
  std::vector<SequenceMarker> markers;
  for (const PlannedSequence& q : plan.sequences) {
    const fs::path marker = fs::path(root) / q.split / (q.id + ".done");
    const std::string name = q.split + "/" + q.id;
    if (!fs::exists(marker)) {
      result.missing.push_back(name + ": not generated (no " + marker.string() + ")");
      continue;
    }
    try {
      SequenceMarker m = readSequenceMarker(marker);
      const std::string why = verifySequence(root, m);
      if (!why.empty()) result.missing.push_back(name + ": " + why);
      else if (m.frames != q.frames)
        result.missing.push_back(name + ": " + std::to_string(m.frames) + " frames, the plan says " +
                                 std::to_string(q.frames));
      else markers.push_back(std::move(m));
    } catch (const std::exception& e) {
      result.missing.push_back(name + ": " + e.what());
    }
  }
  if (!result.missing.empty()) return result;

  // split -> condition -> (sequences, frames)
  std::map<std::string, std::map<std::string, std::pair<uint64_t, uint64_t>>> table;
  const fs::path sums = fs::path(root) / "MANIFEST.sha256", summary = fs::path(root) / "manifest.md";
  std::ofstream out(sums);
  for (size_t i = 0; i < markers.size(); ++i) {
    const PlannedSequence& q = plan.sequences[i];
    auto& cell = table[q.split][q.condition];
    ++cell.first;
    cell.second += markers[i].frames;
    result.frames += markers[i].frames;
    ++result.sequences;
    for (const MarkedFile& f : markers[i].files) {
      out << f.sha256 << "  " << f.relative_path << "\n";
      ++result.files;
    }
  }
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + sums.string());
  std::ofstream md(summary);
  md << "# " << plan.name << "\n\n" << result.sequences << " sequences, " << result.frames << " frames, "
     << result.files << " files (checksums: MANIFEST.sha256).\n\n| split | condition | sequences | frames |\n"
     << "| --- | --- | --- | --- |\n";
  for (const auto& [split, conditions] : table)
    for (const auto& [condition, cell] : conditions)
      md << "| " << split << " | " << condition << " | " << cell.first << " | " << cell.second << " |\n";
  md.flush();
  if (!md) throw std::runtime_error("cannot write " + summary.string());
  return result;
}

}  // namespace viper::dataset
