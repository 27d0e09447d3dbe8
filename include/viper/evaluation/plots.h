// PNG figures of an evaluation report (OpenCV drawing; the core library stays free of OpenCV).
#pragma once

#include "viper/evaluation/evaluation.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace viper {

/// One line of a plot; points with a non-finite x or y are left out (the line breaks there).
struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
};

/// A line plot with axes, ticks, a title and a legend.
struct LinePlot {
  std::string title, x_label, y_label;
  double x_min = 0.0, x_max = 1.0;
  double y_min = 0.0, y_max = 1.0;  ///< y_max <= y_min: from the data (0 to its maximum, padded)
  bool markers = false;             ///< a dot at every point (for few points)
  bool legend_bottom = false;       ///< legend in the bottom right corner instead of the top right
  std::vector<PlotSeries> series;
};

/// Draws `plot` into a width x height BGR image.
cv::Mat renderLinePlot(const LinePlot& plot, int width = 800, int height = 500);

/// `flow_inliers.png`: percentage of pixels with endpoint error <= threshold over 0..5 px, one line
/// per condition (and all) and input (dense, sparse), on all pixels with ground truth. Written only
/// if flow was scored; returns its path or "". Throws std::runtime_error naming the file.
std::string writeFlowInlierPlot(const EvaluationSummary& s, const std::string& dir);
/// `odometry_errors.png`: translation (%) and rotation (deg/m) errors over segment length, one line
/// per condition (and all). Written only if some segment was scored; returns its path or "".
std::string writeOdometryPlot(const EvaluationSummary& s, const std::string& dir);

/// The whole report: the tables (writeReportTables) and the plots above. Returns the paths written.
std::vector<std::string> writeReport(const EvaluationSummary& s, const std::string& dir);

}  // namespace viper
