// The statistics' figures, drawn by the report's line plot (viper_plots).
#include "viper/dataset/statistics_report.h"
#include "viper/report/plot_image.h"

#include <opencv2/core.hpp>

#include <map>

namespace viper::dataset {
namespace {

const char* countedThing(Statistic statistic) {
  switch (statistic) {
    case Statistic::kClassesPerImage:
    case Statistic::kInstancesPerImage: return "share of images";
    case Statistic::kInstancesPerClass: return "share of instances";
    case Statistic::kVehiclesByDistance: return "share of vehicles";
    case Statistic::kPixelsPerClass: return "share of pixels";
  }
  return "share";
}

const char* xLabel(Statistic statistic) {
  switch (statistic) {
    case Statistic::kClassesPerImage: return "scored classes in the image";
    case Statistic::kInstancesPerImage: return "instances in the image";
    case Statistic::kVehiclesByDistance: return "distance from the camera, m (bins from)";
    default: return "";
  }
}

// One panel: a line per group (split or condition), the share of its counts in every bin of the
// dataset (0 where it has none); for classes a bar per group and class, the classes by name.
LinePlot panel(const DatasetStatistics& s, Statistic statistic, const std::string& by,
               const std::vector<std::string>& groups, bool is_split) {
  LinePlot plot;
  plot.title = std::string(statisticTitle(statistic)) + ", by " + by;
  plot.x_label = xLabel(statistic);
  plot.y_label = countedThing(statistic);
  plot.y_min = plot.y_max = 0.0;  // from the data
  const Histogram all = s.pooled(statistic, [](const std::string&, const std::string&) { return true; });
  const double scale = statistic == Statistic::kVehiclesByDistance ? s.distance_bin_m : 1.0;
  plot.bars = binsAreClasses(statistic);
  plot.markers = !plot.bars;
  // x: the class's place among the classes present, or every bin from the first to the last (its
  // lower edge in metres for distances), so that empty bins show as 0.
  std::map<int64_t, double> x;
  if (plot.bars) {
    for (const auto& [bin, unused] : all) {
      const double place = static_cast<double>(x.size());
      x[bin] = place;
      plot.x_tick_labels.push_back(binLabel(s, statistic, bin));
    }
  } else if (!all.empty()) {
    for (int64_t bin = all.begin()->first; bin <= all.rbegin()->first; ++bin) x[bin] = static_cast<double>(bin) * scale;
  }
  if (!x.empty()) {  // half a bin of margin either side
    plot.x_min = x.begin()->second - (plot.bars ? 0.5 : 0.5 * scale);
    plot.x_max = x.rbegin()->second + (plot.bars ? 0.5 : 0.5 * scale);
  }
  for (const std::string& group : groups) {
    const Histogram h = s.pooled(statistic, [&](const std::string& split, const std::string& condition) {
      return (is_split ? split : condition) == group;
    });
    const double n = static_cast<double>(histogramTotal(h));
    if (n == 0) continue;
    PlotSeries series{group, {}, {}};
    for (const auto& [bin, place] : x) {
      const auto it = h.find(bin);
      series.x.push_back(place);
      series.y.push_back(it == h.end() ? 0.0 : static_cast<double>(it->second) / n);
    }
    plot.series.push_back(std::move(series));
  }
  return plot;
}

}  // namespace

void writeStatisticPlot(const DatasetStatistics& s, Statistic statistic, const std::string& path) {
  cv::Mat image;
  cv::hconcat(renderLinePlot(panel(s, statistic, "split", s.splits(), true), 640, 420),
              renderLinePlot(panel(s, statistic, "condition", s.conditions(), false), 640, 420), image);
  writePng(image, path);
}

}  // namespace viper::dataset
