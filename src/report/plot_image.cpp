#include "viper/report/plot_image.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace viper {
namespace {

const cv::Scalar kPalette[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
                               {34, 189, 188}, {207, 190, 23}};
const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225), kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

// A "nice" tick step giving about `target` ticks over `range`.
double tickStep(double range, int target) {
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (raw <= m * mag) return m * mag;
  return 10.0 * mag;
}

std::string tickLabel(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(buf, sizeof(buf), "%.*f", std::max(0, decimals), v);
  return buf;
}

// `text` turned upright (reading upwards), on white.
cv::Mat upright(const std::string& text, double scale) {
  int base = 0;
  const cv::Size ts = cv::getTextSize(text, kFont, scale, 1, &base);
  cv::Mat label(ts.height + base + 4, ts.width + 4, CV_8UC3, kWhite);
  cv::putText(label, text, {2, ts.height + 2}, kFont, scale, kBlack, 1, cv::LINE_AA);
  cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
  return label;
}

}  // namespace

void writePng(const cv::Mat& image, const std::string& path) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  if (!ok) throw std::runtime_error(path + ": cannot write the PNG");
}

cv::Mat renderLinePlot(const LinePlot& plot, int width, int height) {
  cv::Mat img(height, width, CV_8UC3, kWhite);
  std::vector<cv::Mat> categories;
  int bottom = 55;
  for (const std::string& name : plot.x_tick_labels) {
    categories.push_back(upright(name, 0.4));
    bottom = std::max(bottom, categories.back().rows + 36);
  }
  const int left = 70, right = 20, top = 40;
  const cv::Rect area(left, top, width - left - right, height - top - bottom);
  double y_min = plot.y_min, y_max = plot.y_max;
  if (!(y_max > y_min)) {
    y_min = 0.0, y_max = 0.0;
    for (const PlotSeries& s : plot.series)
      for (double v : s.y)
        if (std::isfinite(v)) y_max = std::max(y_max, v);
    y_max = y_max > 0.0 ? 1.1 * y_max : 1.0;
  }
  const double x_min = plot.x_min, x_max = plot.x_max > plot.x_min ? plot.x_max : plot.x_min + 1.0;
  auto to_px = [&](double x, double y) {
    return cv::Point(area.x + static_cast<int>(std::lround((x - x_min) / (x_max - x_min) * area.width)),
                     area.y + area.height - static_cast<int>(std::lround((y - y_min) / (y_max - y_min) * area.height)));
  };

  // Grid and ticks.
  const double xs = tickStep(x_max - x_min, 10), ys = tickStep(y_max - y_min, 8);
  for (size_t i = 0; i < categories.size(); ++i) {
    const cv::Point p = to_px(static_cast<double>(i), y_min);
    const cv::Rect where(p.x - categories[i].cols / 2, area.y + area.height + 4, categories[i].cols, categories[i].rows);
    if (where.x >= 0 && where.x + where.width <= width && where.y + where.height <= height)
      categories[i].copyTo(img(where));
  }
  for (double x = std::ceil(x_min / xs) * xs; categories.empty() && x <= x_max + 1e-9 * xs; x += xs) {
    const cv::Point p = to_px(x, y_min);
    cv::line(img, {p.x, area.y}, {p.x, area.y + area.height}, kGrid, 1);
    const std::string t = tickLabel(x, xs);
    int base = 0;
    const cv::Size ts = cv::getTextSize(t, kFont, 0.4, 1, &base);
    cv::putText(img, t, {p.x - ts.width / 2, area.y + area.height + 16}, kFont, 0.4, kBlack, 1, cv::LINE_AA);
  }
  for (double y = std::ceil(y_min / ys) * ys; y <= y_max + 1e-9 * ys; y += ys) {
    const cv::Point p = to_px(x_min, y);
    cv::line(img, {area.x, p.y}, {area.x + area.width, p.y}, kGrid, 1);
    const std::string t = tickLabel(y, ys);
    int base = 0;
    const cv::Size ts = cv::getTextSize(t, kFont, 0.4, 1, &base);
    cv::putText(img, t, {area.x - ts.width - 6, p.y + 4}, kFont, 0.4, kBlack, 1, cv::LINE_AA);
  }
  cv::rectangle(img, area, kBlack, 1);

  // Labels.
  int base = 0;
  cv::Size ts = cv::getTextSize(plot.title, kFont, 0.6, 1, &base);
  cv::putText(img, plot.title, {(width - ts.width) / 2, 25}, kFont, 0.6, kBlack, 1, cv::LINE_AA);
  ts = cv::getTextSize(plot.x_label, kFont, 0.5, 1, &base);
  cv::putText(img, plot.x_label, {area.x + (area.width - ts.width) / 2, height - 12}, kFont, 0.5, kBlack, 1,
              cv::LINE_AA);
  const cv::Mat label = upright(plot.y_label, 0.5);
  const int ly = std::max(0, area.y + (area.height - label.rows) / 2);
  if (ly + label.rows <= height && label.cols + 4 <= left) label.copyTo(img(cv::Rect(4, ly, label.cols, label.rows)));

  // Lines or bars, clipped to the plot area.
  cv::Mat inner = img(area);
  const cv::Point offset(area.x, area.y);
  const double group_px = 0.8 * area.width / (x_max - x_min);  // the bars of one x
  for (size_t i = 0; i < plot.series.size(); ++i) {
    const PlotSeries& s = plot.series[i];
    const cv::Scalar color = kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))];
    const double bar_px = group_px / static_cast<double>(plot.series.size());
    for (size_t j = 0; plot.bars && j < std::min(s.x.size(), s.y.size()); ++j) {
      if (!std::isfinite(s.x[j]) || !std::isfinite(s.y[j])) continue;
      const cv::Point top_px = to_px(s.x[j], s.y[j]) - offset, base_px = to_px(s.x[j], std::max(y_min, 0.0)) - offset;
      const int x0 = static_cast<int>(std::lround(top_px.x - group_px / 2 + bar_px * static_cast<double>(i)));
      cv::rectangle(inner, cv::Rect(cv::Point(x0, top_px.y), cv::Point(x0 + std::max(1, static_cast<int>(bar_px)), base_px.y)),
                    color, cv::FILLED);
    }
    if (plot.bars) continue;
    bool have_prev = false;
    cv::Point prev;
    for (size_t j = 0; j < std::min(s.x.size(), s.y.size()); ++j) {
      if (!std::isfinite(s.x[j]) || !std::isfinite(s.y[j])) {
        have_prev = false;
        continue;
      }
      const cv::Point p = to_px(s.x[j], s.y[j]) - offset;
      if (have_prev) cv::line(inner, prev, p, color, 2, cv::LINE_AA);
      if (plot.markers) cv::circle(inner, p, 4, color, cv::FILLED, cv::LINE_AA);
      prev = p, have_prev = true;
    }
  }

  // Legend, top right inside the area.
  int lw = 0;
  for (const PlotSeries& s : plot.series) lw = std::max(lw, cv::getTextSize(s.label, kFont, 0.45, 1, &base).width);
  const int row = 18, lx = area.x + area.width - lw - 45;
  const int ly0 = plot.legend_bottom ? area.y + area.height - static_cast<int>(plot.series.size()) * row - 8
                                     : area.y + 10;
  if (!plot.series.empty()) {
    cv::rectangle(img, {lx - 6, ly0 - 6, lw + 45, static_cast<int>(plot.series.size()) * row + 8}, kWhite, cv::FILLED);
    cv::rectangle(img, {lx - 6, ly0 - 6, lw + 45, static_cast<int>(plot.series.size()) * row + 8}, kGrid, 1);
  }
  for (size_t i = 0; i < plot.series.size(); ++i) {
    const cv::Scalar color = kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))];
    const int y = ly0 + static_cast<int>(i) * row + 6;
    cv::line(img, {lx, y}, {lx + 25, y}, color, 2, cv::LINE_AA);
    cv::putText(img, plot.series[i].label, {lx + 32, y + 5}, kFont, 0.45, kBlack, 1, cv::LINE_AA);
  }
  return img;
}

}  // namespace viper
