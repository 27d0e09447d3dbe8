#include "viper/dataset/statistics_report.h"

#include "viper/report/csv_number.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace viper::dataset {
namespace {

auto everything() {
  return [](const std::string&, const std::string&) { return true; };
}
auto inSplit(const std::string& split) {
  return [split](const std::string& s, const std::string&) { return s == split; };
}
auto inCondition(const std::string& condition) {
  return [condition](const std::string&, const std::string& c) { return c == condition; };
}

std::string row(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& c : cells) out += " " + c + " |";
  return out + "\n";
}

// Text columns left, numbers right.
std::string header(const std::vector<std::string>& cells, size_t text_columns = 1) {
  std::string rule = "|";
  for (size_t i = 0; i < cells.size(); ++i) rule += i < text_columns ? " --- |" : " ---: |";
  return row(cells) + rule + "\n";
}

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// Mean of a per-image statistic (its bins are the numbers).
double mean(const Histogram& h) {
  double sum = 0.0;
  for (const auto& [bin, count] : h) sum += static_cast<double>(bin) * static_cast<double>(count);
  return histogramTotal(h) ? sum / static_cast<double>(histogramTotal(h)) : NAN;
}

const char* binHeading(Statistic statistic) {
  if (binsAreClasses(statistic)) return "class";
  if (statistic == Statistic::kVehiclesByDistance) return "distance from (m)";
  return statistic == Statistic::kClassesPerImage ? "classes" : "instances";
}

void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string names(const DatasetStatistics& s, const std::vector<int>& ids) {
  std::string out;
  for (int id : ids) out += (out.empty() ? "" : ", ") + binLabel(s, Statistic::kInstancesPerClass, id);
  return out.empty() ? "none" : out;
}

}  // namespace

std::string binLabel(const DatasetStatistics& s, Statistic statistic, int64_t bin) {
  if (binsAreClasses(statistic))
    return bin >= 0 && static_cast<size_t>(bin) < s.classes.size() ? s.classes[static_cast<size_t>(bin)].name
                                                                    : std::to_string(bin);
  if (statistic == Statistic::kVehiclesByDistance) return csvNumber(static_cast<double>(bin) * s.distance_bin_m);
  return std::to_string(bin);
}

std::string statisticCsv(const DatasetStatistics& s, Statistic statistic) {
  std::string out = "split,condition,bin,count\n";
  for (const std::string& split : s.splits())
    for (const std::string& condition : s.conditions()) {
      const auto cell = s.cells.find({split, condition});
      if (cell == s.cells.end()) continue;
      const auto h = cell->second.histograms.find(statistic);
      if (h == cell->second.histograms.end()) continue;
      for (const auto& [bin, count] : h->second)
        out += split + "," + condition + "," + binLabel(s, statistic, bin) + "," + std::to_string(count) + "\n";
    }
  return out;
}

std::vector<Divergence> divergences(const DatasetStatistics& s) {
  std::vector<Divergence> out;
  const std::vector<std::string> splits = s.splits(), conditions = s.conditions();
  for (Statistic statistic : allStatistics()) {
    for (size_t i = 0; i < splits.size(); ++i)
      for (size_t j = i + 1; j < splits.size(); ++j)
        out.push_back({statistic, "split", splits[i], splits[j],
                       jensenShannonBits(s.pooled(statistic, inSplit(splits[i])), s.pooled(statistic, inSplit(splits[j])))});
    for (size_t i = 0; i < conditions.size(); ++i)
      for (size_t j = i + 1; j < conditions.size(); ++j)
        out.push_back({statistic, "condition", conditions[i], conditions[j],
                       jensenShannonBits(s.pooled(statistic, inCondition(conditions[i])),
                                         s.pooled(statistic, inCondition(conditions[j])))});
  }
  return out;
}

std::string divergenceCsv(const std::vector<Divergence>& d) {
  std::string out = "statistic,between,a,b,jsd_bits\n";
  for (const Divergence& v : d)
    out += std::string(statisticName(v.statistic)) + "," + v.between + "," + v.a + "," + v.b + "," + csvNumber(v.bits) + "\n";
  return out;
}

std::string statisticsMarkdown(const DatasetStatistics& s, const std::string& title) {
  std::ostringstream md;
  uint64_t sequences = 0, images = 0;
  for (const auto& [key, cell] : s.cells) sequences += cell.sequences, images += cell.images;
  md << "# Statistics: " << title << "\n\n"
     << images << " images (frames with a cls or inst file) in " << sequences << " sequences. "
     << "*Classes per image*: the distinct scored classes (class_eval 1 in the class table) of an image's "
        "cls file (its inst file's R channel where cls is missing). *Instances per image*: the distinct "
        "(class, id) pairs with id > 0 of instance classes (instance_eval 1) in its inst file. *Instances per "
        "class*: the same instances by class, an object counted once in every image it is in. *Vehicles by "
        "distance*: the boxes of the bb files of the vehicle classes ("
     << names(s, s.vehicle_class_ids) << ") with visible pixels, by the distance from the camera to the box's "
     << "centre, in " << csvNumber(s.distance_bin_m) << " m bins. *Pixels per class*: from the cls files.\n\n"
     << "Counts by split and condition: `statistics/<statistic>.csv` (`split,condition,bin,count`).\n\n";

  md << "## Per split and condition\n\n"
     << header({"split", "condition", "sequences", "images", "classes per image (mean)",
                "instances per image (mean)", "instances", "vehicles"},
               2);
  auto summary = [&](const std::string& split, const std::string& condition, uint64_t seqs, uint64_t imgs,
                     const std::function<bool(const std::string&, const std::string&)>& take) {
    md << row({split, condition, std::to_string(seqs), std::to_string(imgs),
               fixed(mean(s.pooled(Statistic::kClassesPerImage, take)), 2),
               fixed(mean(s.pooled(Statistic::kInstancesPerImage, take)), 2),
               std::to_string(histogramTotal(s.pooled(Statistic::kInstancesPerClass, take))),
               std::to_string(histogramTotal(s.pooled(Statistic::kVehiclesByDistance, take)))});
  };
  for (const std::string& split : s.splits())
    for (const std::string& condition : s.conditions()) {
      const auto cell = s.cells.find({split, condition});
      if (cell == s.cells.end()) continue;
      summary(split, condition, cell->second.sequences, cell->second.images,
              [&](const std::string& a, const std::string& b) { return a == split && b == condition; });
    }
  summary("all", "all", sequences, images, everything());

  md << "\n## Jensen-Shannon divergence\n\n"
     << "In bits (base-2 logarithm), so between 0 (the same distribution) and 1 (disjoint ones): "
        "JSD(P, Q) = H(M) - (H(P) + H(Q)) / 2 with M = (P + Q) / 2, P and Q the counts of a statistic "
        "normalised to sum to 1. Between splits over every condition, between conditions over every split; "
        "\"-\" where one side has no count. All of them: `statistics/divergence.csv`.\n";
  const std::vector<Divergence> all = divergences(s);
  for (const char* between : {"split", "condition"}) {
    std::vector<std::string> head = {"statistic"};
    for (const Divergence& d : all)
      if (d.between == between && d.statistic == allStatistics().front()) head.push_back(d.a + " / " + d.b);
    if (head.size() == 1) continue;
    md << "\n### Between " << between << "s\n\n" << header(head);
    for (Statistic statistic : allStatistics()) {
      std::vector<std::string> cells = {statisticTitle(statistic)};
      for (const Divergence& d : all)
        if (d.between == between && d.statistic == statistic) cells.push_back(fixed(d.bits, 3));
      md << row(cells);
    }
  }

  for (Statistic statistic : allStatistics()) {
    md << "\n## " << statisticTitle(statistic) << "\n\n![" << statisticTitle(statistic) << "](statistics/"
       << statisticName(statistic) << ".png)\n\n";
    std::vector<std::string> head = {binHeading(statistic)};
    std::vector<Histogram> columns;
    for (const std::string& split : s.splits())
      head.push_back(split), columns.push_back(s.pooled(statistic, inSplit(split)));
    for (const std::string& condition : s.conditions())
      head.push_back(condition), columns.push_back(s.pooled(statistic, inCondition(condition)));
    head.push_back("all");
    columns.push_back(s.pooled(statistic, everything()));
    md << header(head);
    for (const auto& [bin, count] : columns.back()) {
      std::vector<std::string> cells = {binLabel(s, statistic, bin)};
      for (const Histogram& h : columns) cells.push_back(std::to_string(h.count(bin) ? h.at(bin) : 0));
      md << row(cells);
    }
  }
  if (!s.problems.empty()) {
    md << "\n## Files not read\n\n" << s.problems.size() << " problems; the first:\n\n";
    for (size_t i = 0; i < s.problems.size() && i < 20; ++i) md << "- " << s.problems[i] << "\n";
  }
  return md.str();
}

std::vector<std::string> writeStatisticsReport(const DatasetStatistics& s, const std::string& root,
                                               const std::string& title) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(root) / "statistics";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  std::vector<std::string> written;
  for (Statistic statistic : allStatistics()) {
    const fs::path csv = dir / (std::string(statisticName(statistic)) + ".csv");
    const fs::path png = dir / (std::string(statisticName(statistic)) + ".png");
    writeText(csv, statisticCsv(s, statistic));
    writeStatisticPlot(s, statistic, png.string());
    written.push_back(csv.string());
    written.push_back(png.string());
  }
  writeText(dir / "divergence.csv", divergenceCsv(divergences(s)));
  written.push_back((dir / "divergence.csv").string());
  writeText(fs::path(root) / "statistics.md", statisticsMarkdown(s, title));
  written.push_back((fs::path(root) / "statistics.md").string());
  return written;
}

}  // namespace viper::dataset
