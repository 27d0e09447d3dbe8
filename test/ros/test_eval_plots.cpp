// The report's figures: lines land where their values say, and the report writes both PNGs
// (readable back) only when there is something to show.
#include "viper/evaluation/eval_report.h"
#include "viper/evaluation/plots.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>

namespace viper {
namespace {

// Pixels of the first palette colour (BGR 180, 119, 31) in a column of the image.
std::vector<int> rowsOfFirstColour(const cv::Mat& img, int x) {
  std::vector<int> rows;
  for (int y = 0; y < img.rows; ++y) {
    const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
    if (p == cv::Vec3b(180, 119, 31)) rows.push_back(y);
  }
  return rows;
}

TEST(EvalPlots, LineLandsAtItsValue) {
  LinePlot plot;
  plot.title = "t";
  plot.x_min = 0, plot.x_max = 5, plot.y_min = 0, plot.y_max = 100;
  plot.series.push_back({"half", {0.0, 5.0}, {50.0, 50.0}});
  const cv::Mat img = renderLinePlot(plot, 800, 500);
  ASSERT_EQ(img.cols, 800);
  ASSERT_EQ(img.rows, 500);
  // Plot area: x 70..780, y 40..445 (margins 70/20/40/55): y = 50 % lies at row 40 + 405/2.
  const auto rows = rowsOfFirstColour(img, 200);
  ASSERT_FALSE(rows.empty());
  for (int r : rows) EXPECT_NEAR(r, 40 + 405 / 2.0, 2.0);
}

TEST(EvalPlots, NonFiniteValuesBreakTheLine) {
  LinePlot plot;
  plot.x_min = 0, plot.x_max = 4, plot.y_min = 0, plot.y_max = 10;
  plot.series.push_back({"gap", {0, 1, 2, 3, 4}, {5, 5, NAN, 5, 5}});
  const cv::Mat img = renderLinePlot(plot, 800, 500);
  // x = 2 lies at column 70 + 710 / 2 = 425: no line there, but at x = 0.5 and 3.5.
  EXPECT_TRUE(rowsOfFirstColour(img, 425).empty());
  EXPECT_FALSE(rowsOfFirstColour(img, 70 + 710 / 8).empty());
  EXPECT_FALSE(rowsOfFirstColour(img, 70 + 710 * 7 / 8).empty());
}

TEST(EvalPlots, BarsStandOnZeroUpToTheirValueAndCategoriesMakeRoom) {
  LinePlot plot;
  plot.x_min = -0.5, plot.x_max = 1.5, plot.y_min = 0, plot.y_max = 100;
  plot.bars = true;
  plot.series.push_back({"bars", {0.0, 1.0}, {50.0, 100.0}});
  cv::Mat img = renderLinePlot(plot, 800, 500);
  // Area x 70..780, y 40..445: x = 0 at column 70 + 710 / 4, x = 1 at 70 + 710 * 3 / 4.
  auto rows = rowsOfFirstColour(img, 70 + 710 / 4);
  ASSERT_FALSE(rows.empty());
  EXPECT_NEAR(rows.front(), 40 + 405 / 2.0, 2.0) << "top at 50";
  EXPECT_NEAR(rows.back(), 445, 2.0) << "from 0";
  rows = rowsOfFirstColour(img, 70 + 710 * 3 / 4);
  ASSERT_FALSE(rows.empty());
  EXPECT_NEAR(rows.front(), 40, 2.0) << "top at 100";
  EXPECT_TRUE(rowsOfFirstColour(img, 70 + 710 / 2).empty()) << "nothing between the bars";

  plot.x_tick_labels = {"a long category name", "b"};
  img = renderLinePlot(plot, 800, 500);
  rows = rowsOfFirstColour(img, 70 + 710 / 4);
  ASSERT_FALSE(rows.empty());
  EXPECT_LT(rows.back(), 445 - 50) << "the upright names take room below the area";
}

TEST(EvalPlots, ReportWritesBothFiguresOnlyWithData) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "viper_test_eval_plots";
  std::filesystem::remove_all(dir);
  EvaluationOptions o;
  o.odometry_lengths_m = {1.0, 2.0};
  o.odometry_step_frames = 1;
  Evaluation e(ClassTable::load("config/viper_classes.csv"), o);
  const std::vector<float> gt = {1, 0, 2, 0}, pred = {1, 0, 0, 0};
  e.addFlow("day", gt.data(), nullptr, pred.data(), 2);
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d g = Eigen::Isometry3d::Identity(), est = g;
    g.translation().x() = i, est.translation().x() = 1.1 * i;
    e.addPose("day", i, g, est);
  }
  const auto written = writeReport(e.summarize(), dir.string());
  EXPECT_EQ(written.size(), 9u);
  const cv::Mat flow = cv::imread((dir / "flow_inliers.png").string());
  const cv::Mat odo = cv::imread((dir / "odometry_errors.png").string());
  ASSERT_FALSE(flow.empty());
  ASSERT_FALSE(odo.empty());
  EXPECT_EQ(flow.cols, 800);
  EXPECT_EQ(odo.cols, 1280);

  // Without flow or segments, the figures are not written and stale ones are removed.
  Evaluation none(ClassTable::load("config/viper_classes.csv"));
  const std::vector<uint8_t> sem = {3, 3};
  none.addSemantic("day", sem.data(), sem.data(), 2);
  EXPECT_EQ(writeReport(none.summarize(), dir.string()).size(), 7u);
  EXPECT_FALSE(std::filesystem::exists(dir / "flow_inliers.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "odometry_errors.png"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace viper
