// Parity with cityscapesScripts (issue #19): the cases of test/evaluation/data/cityscapes_parity
// (written by write_parity_cases), scored here through Evaluation as the evaluate node scores
// them, against reference.csv, the scores cityscapesScripts' own evaluation gave for the same
// files (scripts/cityscapes_parity.py). Every class IoU, iIoU, AP and AP50 and the four means
// must agree to rounding.
#include "viper/dataset/viper_images.h"
#include "viper/evaluation/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace viper {
namespace {

namespace fs = std::filesystem;
const fs::path kCases = "test/evaluation/data/cityscapes_parity";

struct Row {
  std::string metric;
  int class_id = 0;
  double value = 0.0;
};

// reference.csv: case -> rows.
std::map<std::string, std::vector<Row>> readReference() {
  std::ifstream f(kCases / "reference.csv");
  std::map<std::string, std::vector<Row>> out;
  std::string line;
  if (!std::getline(f, line) || line != "case,metric,class_id,value") {
    ADD_FAILURE() << (kCases / "reference.csv") << ": missing, or not the header case,metric,class_id,value";
    return out;
  }
  for (int number = 2; std::getline(f, line); ++number) {
    std::stringstream s(line);
    std::string name, metric, id, value;
    if (!std::getline(s, name, ',') || !std::getline(s, metric, ',') || !std::getline(s, id, ',') ||
        !std::getline(s, value)) {
      ADD_FAILURE() << "reference.csv:" << number << ": not 4 fields: " << line;
      continue;
    }
    out[name].push_back({metric, std::stoi(id), value == "nan" ? std::nan("") : std::stod(value)});
  }
  return out;
}

// Every frame of one case through Evaluation, under the condition "parity".
EvaluationSummary scoreCase(const fs::path& dir, const ClassTable& classes) {
  Evaluation e(classes);
  std::vector<fs::path> frames;
  for (const auto& entry : fs::directory_iterator(dir / "cls")) frames.push_back(entry.path().stem());
  std::sort(frames.begin(), frames.end());
  for (const fs::path& name : frames) {
    const std::string png = name.string() + ".png";
    const dataset::Image8 cls = dataset::readViperClassImage(dir / "cls" / png);
    const dataset::Image8 pred = dataset::readViperClassImage(dir / "pred_cls" / png);
    const std::vector<int32_t> ids = dataset::viperInstanceIds(dataset::readViperInstanceImage(dir / "inst" / png));
    EvalFrame f;
    f.condition = "parity", f.width = cls.width, f.height = cls.height;
    f.gt_semantic = cls.data.data(), f.gt_instance_ids = ids.data(), f.pred_semantic = pred.data.data();
    e.add("semantic", f);
    e.add("semantic_iiou", f);
    std::vector<PredictedInstance> predictions;
    std::ifstream list(dir / "pred_inst" / (name.string() + ".txt"));
    std::string mask;
    PredictedInstance p;
    while (list >> mask >> p.class_id >> p.score) {
      p.mask = dataset::readViperClassImage(dir / "pred_inst" / mask).data;
      predictions.push_back(p);
    }
    e.addInstances("parity", ids.data(), cls.data.data(), cls.pixels(), predictions);
  }
  return e.summarize();
}

TEST(CityscapesParity, EveryCaseScoresAsTheReference) {
  const ClassTable classes = ClassTable::load("config/viper_classes.csv");
  const auto reference = readReference();
  std::vector<std::string> cases;
  for (const auto& entry : fs::directory_iterator(kCases))
    if (entry.is_directory()) cases.push_back(entry.path().filename().string());
  std::sort(cases.begin(), cases.end());
  ASSERT_EQ(cases, (std::vector<std::string>{"absent_class", "distinct_scores", "groups", "realistic", "ties",
                                             "unscored_instances"}));
  for (const std::string& name : cases) {
    SCOPED_TRACE("case " + name);
    ASSERT_EQ(reference.count(name), 1u) << "reference.csv has no rows of this case";
    const ConditionSummary& all = scoreCase(kCases / name, classes).all;
    const MetricScores &semantic = all.scoresOf("semantic"), &iiou = all.scoresOf("semantic_iiou"),
                       &instances = all.scoresOf("instances");
    int numbers = 0;
    for (const Row& row : reference.at(name)) {
      double ours = std::nan("");
      if (row.metric == "iou") ours = semantic.per_class.at("iou_percent").at(row.class_id);
      else if (row.metric == "ap") ours = instances.per_class.at("ap_percent").at(row.class_id);
      else if (row.metric == "ap50") ours = instances.per_class.at("ap50_percent").at(row.class_id);
      else if (row.metric == "iiou") ours = iiou.per_class.at("iiou_percent").at(row.class_id);
      else if (row.metric == "mean_iou") ours = semantic.values.at("mean_iou");
      else if (row.metric == "mean_iiou") ours = iiou.values.at("mean_iiou");
      else if (row.metric == "mean_ap") ours = instances.values.at("ap");
      else if (row.metric == "mean_ap50") ours = instances.values.at("ap50");
      else ADD_FAILURE() << "unknown metric " << row.metric;
      const std::string what = row.metric + " of class " + std::to_string(row.class_id);
      if (std::isnan(row.value)) {
        EXPECT_TRUE(std::isnan(ours)) << what << ": " << ours << " %, the reference has none";
      } else {
        EXPECT_NEAR(ours / 100.0, row.value, 1e-12) << what;
        ++numbers;
      }
    }
    EXPECT_GE(numbers, 6) << "the case should have numbers to compare";
  }
}

}  // namespace
}  // namespace viper
