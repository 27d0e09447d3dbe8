#include "viper/evaluation/instance_metrics.h"
#include "viper/evaluation/odometry_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace viper {
namespace {

// A 40x20 frame; class 24 (car) is instance-evaluated, classes 0 and 28 (trailer) are not scored
// (void without an instance id), as in config/viper_classes.csv.
constexpr int kW = 40, kH = 20, kCar = 24, kTrailer = 28;

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
  void_class[0] = void_class[kTrailer] = true;
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

// Issue #19, the differences from cityscapesScripts' evalInstanceLevelSemanticLabeling.py. The AP
// of car at each threshold 0.50, 0.55, ..., 0.95 of one frame's predictions (the values are exact
// in binary).
std::vector<double> carAps(const Frame& f, const std::vector<PredictedInstance>& predictions) {
  auto acc = makeAcc();
  acc.add(f.ids.data(), f.classes.data(), f.ids.size(), predictions);
  std::vector<double> aps;
  for (size_t t = 0; t < InstanceApAccumulator::thresholds().size(); ++t) aps.push_back(acc.ap(kCar, t));
  return aps;
}
// `first` values of a, then b.
std::vector<double> steps(size_t first, double a, double b) {
  std::vector<double> v(InstanceApAccumulator::thresholds().size(), b);
  std::fill(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first), a);
  return v;
}

// With every prediction at one score the curve is one point (precision 1/2, recall 1/2: one true,
// one false positive, one car missed) closed by cityscapesScripts' point (recall 0, precision 1):
// step widths 0.25 and 0.25, AP = 0.5 * 0.25 + 1 * 0.25 = 0.375. The curve closed at the last
// precision instead gave 0.5 * 0.5 = 0.25.
TEST(InstanceAp, PredictionsTiedAtTheTopScore) {
  Frame f;
  f.paint(1, kCar, 0, 0, 20, 10);
  f.paint(2, kCar, 20, 0, 20, 10);
  EXPECT_EQ(carAps(f, {box(kCar, 1.0, 0, 0, 20, 10), box(kCar, 1.0, 0, 12, 10, 8)}), steps(0, 0.0, 0.375));
}

// A car predicted (0.9) on a trailer with an instance id: not void (pixels of an instance never
// are), a false positive above the true positive (0.5): AP 0.25. On trailer pixels without an
// instance id the same prediction lies on void and is dropped: AP 1.
TEST(InstanceAp, InstanceOfAnUnscoredClassIsNotVoid) {
  for (int trailer_id : {2, 0}) {
    Frame f;
    f.paint(1, kCar, 0, 0, 20, 10);
    f.paint(trailer_id, kTrailer, 20, 0, 20, 10);
    EXPECT_EQ(carAps(f, {box(kCar, 0.5, 0, 0, 20, 10), box(kCar, 0.9, 20, 0, 20, 10)}),
              steps(0, 0.0, trailer_id != 0 ? 0.25 : 1.0))
        << "trailer id " << trailer_id;
  }
}

// Car pixels without an instance id are the car group (200 px): never a ground truth to find, and
// a car prediction on it is no false positive. P1 (0.9) is the group exactly (IoU 1: dropped at every
// threshold). P2 (0.8, 130 px) has 100 px on the group and 30 on road: IoU 100/230 matches nothing,
// its ignored share 100/130 = 0.77 is above 0.50..0.75 (dropped: AP 1) and not above 0.80..0.95,
// where it is a false positive above the true positive (AP 0.25, as above).
TEST(InstanceAp, GroupPixelsAreIgnoredByTheirClass) {
  Frame f;
  f.paint(1, kCar, 0, 0, 20, 10);
  f.paint(0, kCar, 20, 0, 20, 10);
  const InstanceOverlaps o = makeAcc().overlaps(f.ids.data(), f.classes.data(), kW * kH, 1, {});
  ASSERT_EQ(o.ground_truth.size(), 2u);
  EXPECT_TRUE(o.ground_truth[0].group);
  EXPECT_EQ(o.ground_truth[0].class_id, kCar);
  EXPECT_EQ(o.ground_truth[0].pixels, 200u);
  EXPECT_EQ(carAps(f, {box(kCar, 0.5, 0, 0, 20, 10), box(kCar, 0.9, 20, 0, 20, 10), box(kCar, 0.8, 30, 0, 10, 13)}),
            steps(6, 1.0, 0.25));
}

// A group under 100 px is also small ground truth, and cityscapesScripts adds its pixels to a
// prediction's ignored share twice. P (0.9, 100 px) has 30 px on a 60 px group: ignored share
// 0.6, above 0.50 and 0.55 (dropped: AP 1), not above 0.60..0.95 (a false positive: AP 0.25).
TEST(InstanceAp, SmallGroupCountsTwiceAsCityscapesScriptsDoes) {
  Frame f;
  f.paint(1, kCar, 0, 0, 20, 10);
  f.paint(0, kCar, 20, 0, 6, 10);
  EXPECT_EQ(carAps(f, {box(kCar, 0.5, 0, 0, 20, 10), box(kCar, 0.9, 23, 0, 10, 10)}), steps(2, 1.0, 0.25));
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
