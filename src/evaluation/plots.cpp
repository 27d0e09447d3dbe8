#include "viper/evaluation/plots.h"

#include "viper/evaluation/eval_report.h"

#include <algorithm>
#include <filesystem>

namespace viper {

namespace {

std::vector<const ConditionSummary*> columns(const EvaluationSummary& s) {
  std::vector<const ConditionSummary*> c;
  for (const ConditionSummary& cs : s.conditions) c.push_back(&cs);
  c.push_back(&s.all);
  return c;
}

}  // namespace

std::string writePlot(const EvaluationSummary& s, const MetricLayout& metric, const PlotLayout& plot,
                      const std::string& dir) {
  // The metrics sharing the figure: the metric's group (or itself), each with its own curves.
  std::vector<std::pair<const MetricLayout*, const PlotLayout*>> members;
  for (const MetricLayout& m : s.layouts) {
    if (&m != &metric && (metric.group.empty() || m.group != metric.group)) continue;
    for (const PlotLayout& p : m.plots)
      if (p.file == plot.file && p.panels.size() == plot.panels.size()) members.emplace_back(&m, &p);
  }
  std::vector<cv::Mat> panels;
  for (size_t p = 0; p < plot.panels.size(); ++p) {
    LinePlot lines = plot.panels[p].axes;
    for (const ConditionSummary* c : columns(s))
      for (const auto& [owner, member] : members) {
        const MetricScores& scores = c->scoresOf(owner->key);
        if (!(scores.value(member->when) > 0.0)) continue;
        const PlotLayout::Panel& panel = member->panels[p];
        for (const ReportColumn& curve : panel.curves) {
          const auto y = scores.curves.find(curve.key);
          lines.series.push_back({c->condition + (curve.label.empty() ? "" : " " + curve.label), panel.x,
                                  y == scores.curves.end() ? std::vector<double>() : y->second});
        }
      }
    if (lines.series.empty()) return "";
    panels.push_back(renderLinePlot(lines, plot.width, plot.height));
  }
  if (panels.empty()) return "";
  cv::Mat image;
  if (panels.size() == 1) image = panels[0];
  else cv::hconcat(panels, image);
  const std::string path = (std::filesystem::path(dir) / plot.file).string();
  writePng(image, path);
  return path;
}

std::vector<std::string> writeReport(const EvaluationSummary& s, const std::string& dir) {
  std::vector<std::string> written = writeReportTables(s, dir);
  // A figure with nothing to show is removed, so that no figure of an earlier report stays behind.
  std::vector<std::string> files;
  for (const MetricLayout& m : s.layouts)
    for (const PlotLayout& plot : m.plots) {
      if (std::find(files.begin(), files.end(), plot.file) != files.end()) continue;
      files.push_back(plot.file);
      const std::string path = writePlot(s, m, plot, dir);
      std::error_code ec;
      if (path.empty()) std::filesystem::remove(std::filesystem::path(dir) / plot.file, ec);
      else written.push_back(path);
    }
  return written;
}

}  // namespace viper
