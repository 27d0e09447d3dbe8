// PNG figures of an evaluation report (OpenCV drawing; the core library stays free of OpenCV).
#pragma once

#include "viper/evaluation/evaluation.h"
#include "viper/report/plot_image.h"

#include <string>
#include <vector>

namespace viper {

/// A metric's figure `plot` (PlotLayout) as `dir`/plot.file: the panels side by side. Returns its
/// path, or "" (and writes nothing) if it has no line. Throws std::runtime_error naming the file.
std::string writePlot(const EvaluationSummary& s, const MetricLayout& metric, const PlotLayout& plot,
                      const std::string& dir);

/// The whole report: the tables (writeReportTables) and every metric's figures (a figure without a
/// line is removed). Returns the paths written.
std::vector<std::string> writeReport(const EvaluationSummary& s, const std::string& dir);

}  // namespace viper
