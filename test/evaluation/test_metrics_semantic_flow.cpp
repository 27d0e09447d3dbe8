#include "viper/ground_truth/class_table.h"
#include "viper/evaluation/evaluation.h"
#include "viper/evaluation/flow_metrics.h"
#include "viper/evaluation/semantic_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace viper {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(ClassTable, LoadsTheVIPERTable) {
  const ClassTable t = ClassTable::load("config/viper_classes.csv");
  ASSERT_EQ(t.size(), 32u);
  EXPECT_EQ(t.at(24).name, "car");
  EXPECT_EQ(t.idOf("person"), 20);
  EXPECT_EQ(t.at(3).rgb, (std::array<uint8_t, 3>{{128, 64, 128}}));
  EXPECT_TRUE(t.at(24).instance_eval);
  EXPECT_FALSE(t.at(0).class_eval);
  int scored = 0, instances = 0;
  for (bool b : t.semanticEvalMask()) scored += b;
  for (bool b : t.instanceEvalMask()) instances += b;
  EXPECT_EQ(scored, 23);
  EXPECT_EQ(instances, 10);
}

TEST(ClassTable, BadFileNamesFileAndLine) {
  try {
    ClassTable::load("test/evaluation/data/classes_bad_row.csv");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("classes_bad_row.csv:4"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ClassTable::load("test/evaluation/data/no_such_file.csv"), std::runtime_error);
}

TEST(SemanticConfusion, HandComputedIoU) {
  // Classes 0 (not scored), 1 and 2 (scored).
  SemanticConfusion conf({false, true, true});
  const std::vector<uint8_t> gt = {1, 1, 1, 2, 2, 0, 0};
  const std::vector<uint8_t> pr = {1, 1, 2, 2, 0, 1, 2};
  conf.add(gt.data(), pr.data(), gt.size());
  // class 1: TP 2, FN 1 (predicted 2), FP 0 (gt 0 pixels are ignored) -> 2/3
  // class 2: TP 1, FN 1 (predicted 0), FP 1 (gt 1 predicted 2) -> 1/3
  EXPECT_DOUBLE_EQ(conf.iou(1), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(conf.iou(2), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(conf.meanIou(), 0.5);
  EXPECT_EQ(conf.scoredPixels(), 5u);
  EXPECT_TRUE(std::isnan(conf.iou(0)));
}

// Issue #19: cityscapesScripts averages every scored class with a true positive, false positive or
// false negative; a class predicted but absent from the ground truth has IoU 0 and counts.
TEST(SemanticConfusion, ClassPredictedButAbsentFromGroundTruthCountsAsZero) {
  SemanticConfusion conf({false, true, true, true});
  const std::vector<uint8_t> gt = {1, 1, 0};
  const std::vector<uint8_t> pr = {1, 3, 2};  // class 3 predicted but never in ground truth; 2 only on unscored
  conf.add(gt.data(), pr.data(), gt.size());
  EXPECT_DOUBLE_EQ(conf.iou(1), 0.5);  // TP 1, FN 1
  EXPECT_DOUBLE_EQ(conf.iou(3), 0.0);  // FP 1
  EXPECT_TRUE(std::isnan(conf.iou(2)));  // a prediction on an unscored pixel is no false positive
  EXPECT_DOUBLE_EQ(conf.meanIou(), (0.5 + 0.0) / 2);
}

TEST(SemanticConfusion, EmptyAndMerge) {
  SemanticConfusion a({false, true}), b({false, true});
  EXPECT_TRUE(std::isnan(a.meanIou()));
  const uint8_t one = 1;
  b.add(&one, &one, 1);
  a.merge(b);
  EXPECT_DOUBLE_EQ(a.meanIou(), 1.0);
  EXPECT_THROW(a.merge(SemanticConfusion({true, true})), std::invalid_argument);
  EXPECT_THROW(a.add(nullptr, &one, 1), std::invalid_argument);
}

TEST(FlowErrorAccumulator, HandComputedScores) {
  // Errors: 0, 1, 2.5, 6 (outlier: > 3 px and > 5% of |gt| = 10 px), and one invalid gt pixel.
  const std::vector<float> gt = {10, 0, 10, 0, 10, 0, 10, 0, kNaN, 0};
  const std::vector<float> pr = {10, 0, 11, 0, 10, 2.5f, 4, 0, 3, 3};
  FlowErrorAccumulator acc;
  acc.add(gt.data(), pr.data(), nullptr, 5);
  EXPECT_EQ(acc.scoredPixels(), 4u);
  EXPECT_DOUBLE_EQ(acc.averageEndpointError(), (0 + 1 + 2.5 + 6) / 4.0);
  // WAUC: mean of (1 - e/5)^2 with 0 for e >= 5.
  EXPECT_NEAR(acc.wauc(), 100.0 * (1.0 + 0.64 + 0.25 + 0.0) / 4.0, 1e-9);
  EXPECT_DOUBLE_EQ(acc.outlierPercent(), 25.0);
  EXPECT_DOUBLE_EQ(acc.inlierPercent(1.5), 50.0);
  EXPECT_DOUBLE_EQ(acc.inlierPercent(5.0), 75.0);
}

TEST(FlowErrorAccumulator, WaucMatchesNumericIntegralOfTheCurve) {
  std::vector<float> gt, pr;
  for (int i = 0; i < 200; ++i) {
    gt.insert(gt.end(), {0.f, 0.f});
    pr.insert(pr.end(), {0.037f * i, 0.f});  // errors 0 .. 7.4 px
  }
  FlowErrorAccumulator acc;
  acc.add(gt.data(), pr.data(), nullptr, 200);
  double num = 0.0, den = 0.0;
  const int steps = 100000;
  for (int s = 0; s < steps; ++s) {
    const double x = (s + 0.5) * 5.0 / steps, w = 1.0 - x / 5.0;
    int inl = 0;
    for (int i = 0; i < 200; ++i) inl += 0.037f * i <= x;
    num += w * inl / 200.0;
    den += w;
  }
  EXPECT_NEAR(acc.wauc(), 100.0 * num / den, 1e-3);
}

// WaucMode::kSampled against its definition taken literally (Spring's getWAUC: for each threshold
// i/20 px count the errors <= it, weight 1 - (i-1)/100), on errors that lie exactly on thresholds
// (0.25 = 5/20, 0.5, 1, 2.5, 5), between them, past 5 px, and an invalid prediction. By hand for
// 0, 1, 2.5 and 6 px: weights from threshold 1, 20 and 50 on sum to 50.5, 33.21 and 13.26.
TEST(FlowErrorAccumulator, SampledWaucAsItsDefinition) {
  const std::vector<float> errors = {0, 0.25f, 0.5f, 1, 1.3f, 2.5f, 4.99f, 5, 5.5f, kNaN};
  std::vector<float> gt, pr;
  for (float e : errors) gt.insert(gt.end(), {2, 1}), pr.insert(pr.end(), {2 + e, 1});
  FlowErrorAccumulator sampled(WaucMode::kSampled), integral;
  sampled.add(gt.data(), pr.data(), nullptr, errors.size());
  integral.add(gt.data(), pr.data(), nullptr, errors.size());
  double sum = 0.0, weights = 0.0;
  for (int i = 1; i <= 100; ++i) {
    const double w = 1.0 - (i - 1) / 100.0, threshold = i / 20.0;
    int within = 0;
    for (float e : errors) within += static_cast<double>(2 + e) - 2 <= threshold;  // NaN: never
    sum += w * within, weights += w;
  }
  EXPECT_NEAR(sampled.wauc(), 100.0 * sum / (weights * errors.size()), 1e-12);
  EXPECT_GT(sampled.wauc(), integral.wauc()) << "the samples never lie under the integral";
  EXPECT_EQ(sampled.averageEndpointError(), integral.averageEndpointError());

  FlowErrorAccumulator hand(WaucMode::kSampled);
  const std::vector<float> g = {10, 0, 10, 0, 10, 0, 10, 0}, p = {10, 0, 11, 0, 10, 2.5f, 4, 0};
  hand.add(g.data(), p.data(), nullptr, 4);
  EXPECT_NEAR(hand.wauc(), 100.0 * (50.5 + 33.21 + 13.26 + 0) / (4 * 50.5), 1e-9);
  EXPECT_THROW(hand.merge(integral), std::invalid_argument);
}

TEST(FlowErrorAccumulator, MaskAndInvalidPredictions) {
  const std::vector<float> gt = {1, 1, 1, 1, 1, 1};
  const std::vector<float> pr = {1, 1, kNaN, 0, 9, 9};
  const std::vector<uint8_t> mask = {1, 1, 0};
  FlowErrorAccumulator acc;
  acc.add(gt.data(), pr.data(), mask.data(), 3);
  EXPECT_EQ(acc.scoredPixels(), 2u);
  EXPECT_EQ(acc.invalidPredictions(), 1u);
  EXPECT_DOUBLE_EQ(acc.averageEndpointError(), 0.0);
  EXPECT_DOUBLE_EQ(acc.outlierPercent(), 50.0);  // the invalid prediction is an outlier
  EXPECT_DOUBLE_EQ(acc.wauc(), 50.0);
}

TEST(FlowErrorAccumulator, AllInvalidGroundTruthGivesNaN) {
  const std::vector<float> gt = {kNaN, kNaN};
  const std::vector<float> pr = {0, 0};
  FlowErrorAccumulator acc;
  acc.add(gt.data(), pr.data(), nullptr, 1);
  EXPECT_EQ(acc.scoredPixels(), 0u);
  EXPECT_TRUE(std::isnan(acc.wauc()));
  EXPECT_TRUE(std::isnan(acc.averageEndpointError()));
  EXPECT_TRUE(std::isnan(acc.outlierPercent()));
}

// KITTI's interpolateBackground, step by step on a 5x4 image: the inner gap of row 0 takes the
// per-component minimum of its neighbours, row ends copy the row's first and last vector; row 1
// has none and lies between rows with vectors, which KITTI leaves missing (its column pass only
// extends the top and the bottom); row 3 copies row 2 from above.
TEST(FillMissingFlow, AsTheKittiDevkit) {
  const float N = kNaN;
  std::vector<float> uv = {1, 5, N, N, N, 0, 3, 2, N, N,   // row 0
                           N, N, N, N, N, N, N, N, N, N,   // row 1
                           N, 0, 7, 1, N, N, N, N, N, N,   // row 2
                           N, N, N, N, N, N, N, N, N, N};  // row 3
  fillMissingFlow(uv.data(), 5, 4);
  const std::vector<float> row0 = {1, 5, 1, 2, 1, 2, 3, 2, 3, 2}, row2(10, 0);
  EXPECT_EQ(std::vector<float>(uv.begin(), uv.begin() + 10), row0);
  for (int i = 10; i < 20; ++i) EXPECT_TRUE(std::isnan(uv[i])) << i;
  for (int y : {2, 3})
    for (int x = 0; x < 5; ++x) {
      EXPECT_EQ(uv[2 * (y * 5 + x)], 7) << x << "," << y;
      EXPECT_EQ(uv[2 * (y * 5 + x) + 1], 1) << x << "," << y;
    }
  std::vector<float> none(8, N);
  fillMissingFlow(none.data(), 2, 2);  // nothing to fill from
  for (float f : none) EXPECT_TRUE(std::isnan(f));
  EXPECT_THROW(fillMissingFlow(nullptr, 2, 2), std::invalid_argument);
}

// The option through the flow metric: a missing vector between (1, 0) and (3, 0) is an invalid
// outlier by default (EPE 2/5 over the other pixels, Fl 1/6) and (1, 0) with flow_fill_missing
// (EPE 2/6, no outlier, nothing invalid).
TEST(FillMissingFlow, OptionOfTheFlowMetric) {
  const ClassTable classes = ClassTable::load("config/viper_classes.csv");
  const std::vector<float> gt = {1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0};
  const std::vector<float> pred = {1, 0, kNaN, kNaN, 3, 0, 1, 0, 1, 0, 1, 0};
  for (bool fill : {false, true}) {
    EvaluationOptions options;
    options.flow_fill_missing = fill;
    Evaluation e(classes, options);
    EvalFrame f;
    f.condition = "day", f.width = 3, f.height = 2, f.gt_flow = gt.data(), f.pred_flow = pred.data();
    e.add("flow", f);
    // The summary held: scoresOf refers into it (a temporary's would dangle; ASan found that here).
    const EvaluationSummary summary = e.summarize();
    const MetricScores& s = summary.all.scoresOf("flow");
    EXPECT_DOUBLE_EQ(s.values.at("epe_px"), fill ? 2.0 / 6 : 2.0 / 5) << fill;
    EXPECT_DOUBLE_EQ(s.values.at("outlier_percent"), fill ? 0.0 : 100.0 / 6) << fill;
    EXPECT_DOUBLE_EQ(s.values.at("invalid"), fill ? 0.0 : 1.0) << fill;
  }
  EvaluationOptions sampled;
  sampled.flow_wauc = WaucMode::kSampled;
  Evaluation e(classes, sampled);
  e.addFlow("day", gt.data(), nullptr, pred.data(), 6);  // errors 0 (x4) and 2 px; one invalid
  // Within every threshold, within those from 2 px (i = 40) on whose weights sum to 61 - 42.09 = 18.91, none.
  const EvaluationSummary summary = e.summarize();
  const MetricScores& scores = summary.all.scoresOf("flow");
  EXPECT_NEAR(scores.values.at("wauc"), 100.0 * (4 * 50.5 + 18.91) / (6 * 50.5), 1e-9);
  EXPECT_EQ(scores.values.at("noc_wauc"), scores.values.at("wauc")) << "no mask: every pixel is visible";
  EXPECT_TRUE(std::isnan(pred[2])) << "the prediction itself is left as it is";
}

}  // namespace
}  // namespace viper
