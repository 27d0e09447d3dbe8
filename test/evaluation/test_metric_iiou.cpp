// The plug-in metric "semantic_iiou" (Cityscapes iIoU) on a hand-computed case, through the
// generic Evaluation::add() and the report.
#include "viper/evaluation/eval_report.h"
#include "viper/evaluation/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace viper {
namespace {

constexpr uint8_t kUnlabeled = 0, kRoad = 3, kCar = 24, kBus = 26;

bool hasLine(const std::string& text, const std::string& line) {
  std::istringstream s(text);
  for (std::string l; std::getline(s, l);)
    if (l == line) return true;
  return false;
}

EvalFrame row(const std::string& condition, const std::vector<uint8_t>& gt, const std::vector<int32_t>& ids,
              const std::vector<uint8_t>& pred) {
  EvalFrame f;
  f.condition = condition;
  f.width = static_cast<uint32_t>(gt.size()), f.height = 1;
  f.gt_semantic = gt.data(), f.gt_instance_ids = ids.data(), f.pred_semantic = pred.data();
  return f;
}

// day: car 1 (8 px, 6 predicted car), car 2 (2 px, none predicted car), 2 road pixels (one
// predicted car: a false positive), 1 unlabeled pixel predicted car (not scored).
// rain: car 3 (5 px, all predicted car).
// Average car size over every instance seen: (8 + 2 + 5) / 3 = 5 px.
// day:  wTP = 5 (6/8 + 0/2) = 3.75, wFN = 5 (2/8 + 2/2) = 6.25, FP = 1: iIoU = 3.75 / 11.
// rain: wTP = 5, nothing else: 100.
// all:  wTP = 5 (0.75 + 1) = 8.75, wFN = 6.25, FP = 1: iIoU = 8.75 / 16 = 54.6875 %.
Evaluation example() {
  Evaluation e(ClassTable::load("config/viper_classes.csv"));
  const std::vector<uint8_t> gt_day = {kCar, kCar, kCar, kCar, kCar, kCar, kCar, kCar, kCar, kCar, kRoad, kRoad,
                                       kUnlabeled};
  const std::vector<int32_t> ids_day = {1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 0, 0, 0};
  const std::vector<uint8_t> pred_day = {kCar, kCar, kCar, kCar, kCar, kCar, kRoad, kRoad, kRoad, kRoad, kCar, kRoad,
                                         kCar};
  EXPECT_EQ(e.add("semantic_iiou", row("day", gt_day, ids_day, pred_day)), 12u);  // scored pixels
  const std::vector<uint8_t> gt_rain(5, kCar);
  const std::vector<int32_t> ids_rain(5, 3);
  EXPECT_EQ(e.add("semantic_iiou", row("rain", gt_rain, ids_rain, gt_rain)), 5u);
  return e;
}

TEST(MetricIiou, IsRegisteredWithItsInputs) {
  const Evaluation e(ClassTable::load("config/viper_classes.csv"));
  const Metric* m = e.metric("semantic_iiou");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->inputs(), kGtSemantic | kGtInstanceIds | kPredSemantic);
  EXPECT_EQ(m->layout().key, "semantic_iiou");
  EXPECT_THROW(Evaluation(ClassTable::load("config/viper_classes.csv")).add("no_such_metric", EvalFrame{}),
               std::invalid_argument);
}

TEST(MetricIiou, HandComputedCase) {
  const EvaluationSummary s = example().summarize();
  ASSERT_EQ(s.conditions.size(), 2u);
  const MetricScores& day = s.conditions[0].scoresOf("semantic_iiou");
  EXPECT_EQ(s.conditions[0].condition, "day");
  EXPECT_EQ(day.frames, 1u);
  EXPECT_NEAR(day.per_class.at("iiou_percent")[kCar], 100.0 * 3.75 / 11.0, 1e-12);
  EXPECT_TRUE(std::isnan(day.per_class.at("iiou_percent")[kBus]));   // neither in ground truth nor predicted
  EXPECT_TRUE(std::isnan(day.per_class.at("iiou_percent")[kRoad]));  // not an instance class
  EXPECT_NEAR(day.values.at("mean_iiou"), 100.0 * 3.75 / 11.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.conditions[1].scoresOf("semantic_iiou").values.at("mean_iiou"), 100.0);
  const MetricScores& all = s.all.scoresOf("semantic_iiou");
  EXPECT_EQ(all.frames, 2u);
  EXPECT_DOUBLE_EQ(all.per_class.at("iiou_percent")[kCar], 54.6875);
  EXPECT_DOUBLE_EQ(all.values.at("mean_iiou"), 54.6875);
  // The other metrics saw nothing.
  EXPECT_EQ(s.all.scoresOf("semantic").frames, 0u);
}

TEST(MetricIiou, Report) {
  const EvaluationSummary s = example().summarize();
  const std::string y = scoresYaml(s);
  EXPECT_TRUE(hasLine(y, "  semantic_iiou: {frames: 2, mean_iiou: 54.6875}")) << y;
  EXPECT_TRUE(hasLine(y, "    semantic_iiou: {frames: 1, mean_iiou: 100}")) << y;
  const std::string md = reportMarkdown(s);
  EXPECT_TRUE(hasLine(md, "| condition | iIoU % |")) << md;
  EXPECT_TRUE(hasLine(md, "| **all** | 54.69 |")) << md;
  EXPECT_TRUE(hasLine(md, "| car | 34.09 | 100.00 | 54.69 |")) << md;
  EXPECT_TRUE(hasLine(md, "| **mean** | **34.09** | **100.00** | **54.69** |")) << md;
  const std::string csv = tableCsv(s, "semantic_iiou.csv");
  EXPECT_TRUE(hasLine(csv, "condition,class_id,class_name,iiou_percent")) << csv;
  EXPECT_TRUE(hasLine(csv, "all,24,car,54.6875")) << csv;
  EXPECT_TRUE(hasLine(csv, "rain,-1,mean,100")) << csv;
}

}  // namespace
}  // namespace viper
