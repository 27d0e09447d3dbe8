// PNG figures of an evaluation report (OpenCV drawing; the core library stays free of OpenCV).
#pragma once

#include "viper/evaluation/evaluation.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace viper {

/// Draws `plot` into a width x height BGR image.
cv::Mat renderLinePlot(const LinePlot& plot, int width = 800, int height = 500);

/// Writes `image` as a PNG file `path`. Throws std::runtime_error naming the file if it cannot.
void writePng(const cv::Mat& image, const std::string& path);

/// A metric's figure `plot` (PlotLayout) as `dir`/plot.file: the panels side by side. Returns its
/// path, or "" (and writes nothing) if it has no line. Throws std::runtime_error naming the file.
std::string writePlot(const EvaluationSummary& s, const MetricLayout& metric, const PlotLayout& plot,
                      const std::string& dir);

/// The whole report: the tables (writeReportTables) and every metric's figures (a figure without a
/// line is removed). Returns the paths written.
std::vector<std::string> writeReport(const EvaluationSummary& s, const std::string& dir);

}  // namespace viper
