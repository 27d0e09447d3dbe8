// Plots drawn as images (OpenCV): the evaluation report's figures and the dataset statistics'.
#pragma once

#include "viper/report/line_plot.h"

#include <opencv2/core.hpp>

#include <string>

namespace viper {

/// Draws `plot` into a width x height BGR image.
cv::Mat renderLinePlot(const LinePlot& plot, int width = 800, int height = 500);

/// Writes `image` as a PNG file `path`. Throws std::runtime_error naming the file if it cannot.
void writePng(const cv::Mat& image, const std::string& path);

}  // namespace viper
