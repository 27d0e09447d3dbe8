#include "viper/evaluation/instance_metrics.h"
#include "viper/evaluation/odometry_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace viper {
namespace {

// A 40x20 frame; class 24 (car) is instance-evaluated, class 0 is void.
constexpr int kW = 40, kH = 20, kCar = 24;

struct Frame {
  std::vector<int32_t> ids = std::vector<int32_t>(kW * kH, 0);
  std::vector<uint8_t> classes = std::vector<uint8_t>(kW * kH, 3);  // road (scored, not void)
  void paint(int id, int cls, int x0, int y0, int w, int h) {
    for (int y = y0; y < y0 + h; ++y)
      for (int x = x0; x < x0 + w; ++x) ids[y * kW + x] = id, classes[y * kW + x] = static_cast<uint8_t>(cls);
  }
};

PredictedInstance box(int cls, double score, int x0, int y0, int w, int h) {
  PredictedInstance p;
  p.class_id = cls;
  p.score = score;
  p.mask.assign(kW * kH, 0);
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) p.mask[y * kW + x] = 1;
  return p;
}

InstanceApAccumulator makeAcc() {
  std::vector<bool> eval(32, false), void_class(32, false);
  eval[kCar] = true;
  void_class[0] = true;
  return InstanceApAccumulator(eval, void_class);
}

TEST(InstanceAp, PerfectPredictionScoresOne) {
  Frame f;
  f.paint(7, kCar, 0, 0, 20, 10);  // 200 px
  auto acc = makeAcc();
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(), {box(kCar, 0.9, 0, 0, 20, 10)});
  EXPECT_DOUBLE_EQ(acc.classAp(kCar), 1.0);
  EXPECT_DOUBLE_EQ(acc.meanAp(), 1.0);
  EXPECT_DOUBLE_EQ(acc.meanAp50(), 1.0);
}

TEST(InstanceAp, PartialOverlapCountsOnlyBelowItsIoU) {
  Frame f;
  f.paint(7, kCar, 0, 0, 20, 10);
  auto acc = makeAcc();
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(), {box(kCar, 0.9, 0, 0, 15, 10)});  // IoU 0.75
  for (size_t t = 0; t < 5; ++t) EXPECT_DOUBLE_EQ(acc.ap(kCar, t), 1.0) << "threshold " << t;
  for (size_t t = 5; t < 10; ++t) EXPECT_DOUBLE_EQ(acc.ap(kCar, t), 0.0) << "threshold " << t;
  EXPECT_DOUBLE_EQ(acc.classAp(kCar), 0.5);
  EXPECT_DOUBLE_EQ(acc.classAp50(kCar), 1.0);
}

TEST(InstanceAp, HigherScoredFalsePositiveFollowsCityscapesStepIntegration) {
  Frame f;
  f.paint(7, kCar, 0, 0, 20, 10);
  auto acc = makeAcc();
  // True positive at 0.5, a false positive on road at 0.9: precision 0.5 at recall 1, and the
  // step-wise integral of cityscapesScripts gives 0.5 * 0.5 = 0.25.
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(),
          {box(kCar, 0.5, 0, 0, 20, 10), box(kCar, 0.9, 25, 12, 10, 8)});
  EXPECT_DOUBLE_EQ(acc.classAp50(kCar), 0.25);
}

TEST(InstanceAp, DuplicateIsFalsePositiveAndVoidPredictionIsIgnored) {
  Frame f;
  f.paint(7, kCar, 0, 0, 20, 10);
  f.paint(0, 0, 25, 10, 15, 10);  // void area
  auto acc = makeAcc();
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(),
          {box(kCar, 0.9, 0, 0, 20, 10), box(kCar, 0.8, 0, 0, 20, 10), box(kCar, 0.95, 25, 10, 15, 10)});
  // The void prediction is dropped; the duplicate (lower score) is a false positive ranked last,
  // which costs nothing in the step integral.
  EXPECT_DOUBLE_EQ(acc.classAp50(kCar), 1.0);
}

TEST(InstanceAp, SmallGroundTruthIsIgnoredAndNoPredictionsScoreZero) {
  Frame f;
  f.paint(3, kCar, 0, 0, 9, 9);  // 81 px < 100: ignored
  auto acc = makeAcc();
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(), {box(kCar, 0.9, 0, 0, 9, 9)});
  EXPECT_TRUE(std::isnan(acc.classAp(kCar)));
  EXPECT_TRUE(std::isnan(acc.meanAp()));

  Frame g;
  g.paint(4, kCar, 0, 0, 20, 10);
  acc.add(g.ids.data(), g.classes.data(), g.ids.size(), {});
  EXPECT_DOUBLE_EQ(acc.classAp(kCar), 0.0);
  EXPECT_THROW(acc.add(g.ids.data(), g.classes.data(), 10, {box(kCar, 1, 0, 0, 1, 1)}), std::invalid_argument);
}

std::vector<Eigen::Isometry3d> straightLine(size_t n) {
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation() = Eigen::Vector3d(static_cast<double>(i), 0.0, 0.0);  // 1 m per frame
    poses.push_back(p);
  }
  return poses;
}

TEST(KittiOdometry, PerfectEstimateHasZeroErrorAndKittiSegmentCounts) {
  const auto gt = straightLine(1001);
  const auto errors = kittiSegmentErrors(gt, gt);
  const OdometryScores s = summarizeSegments(errors);
  // Length L from first frame f needs frame f + L + 1 <= 1000: starts 0, 10, ... <= 999 - L.
  EXPECT_EQ(s.segments_per_length[0], 90u);  // 100 m: starts 0..890
  EXPECT_EQ(s.segments_per_length[7], 20u);  // 800 m: starts 0..190
  EXPECT_NEAR(s.translation_percent, 0.0, 1e-12);
  EXPECT_NEAR(s.rotation_deg_per_m, 0.0, 1e-6);
}

TEST(KittiOdometry, ScaleErrorIsTranslationPercent) {
  const auto gt = straightLine(1001);
  auto est = gt;
  for (auto& p : est) p.translation() *= 1.01;
  const OdometryScores s = summarizeSegments(kittiSegmentErrors(gt, est));
  // Segments are L + 1 metres long (first frame strictly beyond L): error 0.01 (L + 1) / L.
  for (size_t i = 0; i < s.lengths_m.size(); ++i)
    EXPECT_NEAR(s.translation_percent_by_length[i], (s.lengths_m[i] + 1) / s.lengths_m[i], 1e-9);
  EXPECT_NEAR(s.rotation_deg_per_m, 0.0, 1e-6);
}

TEST(KittiOdometry, HeadingDriftIsRotationPerMetre) {
  const auto gt = straightLine(1001);
  auto est = gt;
  for (size_t i = 0; i < est.size(); ++i) est[i].linear() = Eigen::AngleAxisd(1e-3 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const OdometryScores s = summarizeSegments(kittiSegmentErrors(gt, est));
  for (size_t i = 0; i < s.lengths_m.size(); ++i)
    EXPECT_NEAR(s.rotation_deg_per_m_by_length[i], 1e-3 * (s.lengths_m[i] + 1) / s.lengths_m[i] * 180.0 / M_PI, 1e-9);
}

TEST(KittiOdometry, ShortTrajectoryHasNoSegments) {
  const auto gt = straightLine(50);
  const OdometryScores s = summarizeSegments(kittiSegmentErrors(gt, gt));
  EXPECT_EQ(s.segments, 0u);
  EXPECT_TRUE(std::isnan(s.translation_percent));
  EXPECT_THROW(kittiSegmentErrors(gt, straightLine(49)), std::invalid_argument);
}

}  // namespace
}  // namespace viper
