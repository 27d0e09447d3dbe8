// A line (or bar) plot as data: axes, ticks, series. Shared by the evaluation report and the
// dataset statistics; drawn by plot_image.h (OpenCV), so this header needs none.
#pragma once

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
  /// Categories instead of numeric x ticks: label i is written upright under x = i.
  std::vector<std::string> x_tick_labels;
  /// Series as bars side by side around each x (1 apart), from 0, instead of lines.
  bool bars = false;
  std::vector<PlotSeries> series;
};

}  // namespace viper
