// The evaluation accumulators and the report's tables on small hand-computed cases: every number
// below is worked out in the comments, and checked as the text the report files carry.
#include "viper/evaluation/eval_report.h"
#include "viper/evaluation/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace viper {
namespace {

const float kNaNf = std::nanf("");
constexpr int kRoad = 3, kSidewalk = 4, kTree = 7, kCar = 24, kBus = 26;

ClassTable classes() { return ClassTable::load("config/viper_classes.csv"); }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream s(text);
  for (std::string l; std::getline(s, l);) out.push_back(l);
  return out;
}

bool hasLine(const std::string& text, const std::string& line) {
  for (const std::string& l : lines(text))
    if (l == line) return true;
  return false;
}

std::string readFile(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A metric's number, count, per-class vector and curve in a summary.
double value(const ConditionSummary& c, const std::string& metric, const std::string& key) {
  return c.scoresOf(metric).value(key);
}
uint64_t count(const ConditionSummary& c, const std::string& metric, const std::string& key) {
  return static_cast<uint64_t>(value(c, metric, key));
}
const std::vector<double>& perClass(const ConditionSummary& c, const std::string& metric, const std::string& key) {
  return c.scoresOf(metric).per_class.at(key);
}
const std::vector<double>& curve(const ConditionSummary& c, const std::string& metric, const std::string& key) {
  return c.scoresOf(metric).curves.at(key);
}
const MetricLayout& layoutOf(const EvaluationSummary& s, const std::string& metric) {
  for (const MetricLayout& m : s.layouts)
    if (m.key == metric) return m;
  throw std::out_of_range(metric);
}

// 20x10 frame: a car (id 1) on the left half and a bus (id 2) on the right half, 100 px each.
struct InstanceFrame {
  static constexpr int kW = 20, kH = 10;
  std::vector<int32_t> ids = std::vector<int32_t>(kW * kH, 0);
  std::vector<uint8_t> classes = std::vector<uint8_t>(kW * kH, kRoad);
  void paint(int id, int cls, int x0, int x1) {
    for (int y = 0; y < kH; ++y)
      for (int x = x0; x < x1; ++x) ids[y * kW + x] = id, classes[y * kW + x] = static_cast<uint8_t>(cls);
  }
  static PredictedInstance mask(int cls, double score, int x0, int x1, int rows = kH) {
    PredictedInstance p;
    p.class_id = cls, p.score = score;
    p.mask.assign(kW * kH, 0);
    for (int y = 0; y < rows; ++y)
      for (int x = x0; x < x1; ++x) p.mask[y * kW + x] = 1;
    return p;
  }
};

EvaluationOptions smallOdometry() {
  EvaluationOptions o;
  o.odometry_lengths_m = {1.0, 2.0};
  o.odometry_step_frames = 1;
  return o;
}

Eigen::Isometry3d at(double x) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  return t;
}

// The whole worked example: two conditions, every metric.
Evaluation example() {
  Evaluation e(classes(), smallOdometry());
  // Semantic, day: road 4 px (3 right, 1 called car), car 3 px (2 right, 1 called tree), one
  // unlabeled px (ignored). Road IoU 3/4, car IoU 2/(2+1+1) = 1/2; tree has only a false positive
  // (IoU 0: in the mean, as in cityscapesScripts); sky is predicted on an ignored pixel only (NaN,
  // not in the mean). Mean = (75 + 50 + 0) / 3.
  const std::vector<uint8_t> gt_day = {3, 3, 3, 3, 24, 24, 24, 0}, pred_day = {3, 3, 3, 24, 24, 24, 7, 2};
  e.addSemantic("day", gt_day.data(), pred_day.data(), gt_day.size());
  // Rain: road 2 px, car 2 px, all right: 100. Over all: road 5/(5+1), car 4/(4+1+1) and tree 0.
  const std::vector<uint8_t> gt_rain = {3, 3, 24, 24};
  e.addSemantic("rain", gt_rain.data(), gt_rain.data(), gt_rain.size());

  // Instances, day: the car exactly (score 0.9) -> AP 100 at every threshold; the bus by a 9x8 px
  // mask inside its 10x10 (IoU 0.72 exceeds 0.50..0.70, not 0.75..0.95) -> AP 50, AP50 100.
  // Mean 75, AP50 100.
  InstanceFrame day;
  day.paint(1, kCar, 0, 10);
  day.paint(2, kBus, 10, 20);
  e.addInstances("day", day.ids.data(), day.classes.data(), day.ids.size(),
                 {InstanceFrame::mask(kCar, 0.9, 0, 10), InstanceFrame::mask(kBus, 0.8, 10, 19, 8)});
  // Rain: a car and no prediction: car AP 0 (rain mean 0). Over all: the car has 1 TP of 2 ground
  // truths at every threshold -> AP 50 (precision 1 up to recall 0.5); bus as in day -> mean
  // (50 + 50) / 2 = 50, AP50 (50 + 100) / 2 = 75.
  InstanceFrame rain;
  rain.paint(5, kCar, 0, 10);
  e.addInstances("rain", rain.ids.data(), rain.classes.data(), rain.ids.size(), {});

  // Dense flow, day: 4 px; the last has no ground truth. Errors 0, 2.5 and 10 px; the 10 px one is
  // occluded. All: EPE 12.5/3, WAUC (1 + (1-2.5/5)^2 + 0)/3 = 1.25/3, Fl 1/3 (10 > 3 px and > 5 %).
  // Noc: EPE 1.25, WAUC 62.5, Fl 0.
  const std::vector<float> gt_flow = {1, 0, 0, 0, 10, 0, kNaNf, kNaNf}, pred_flow = {1, 0, 0, 2.5f, 0, 0, 0, 0};
  const std::vector<uint8_t> visible = {255, 255, 0, 255};
  e.addFlow("day", gt_flow.data(), visible.data(), pred_flow.data(), 4);

  // Sparse flow, day: a 3x2 image of flow (1, 1), undefined at (2, 1), occluded at (1, 1). Vectors:
  // exact at (0, 0); (1.4, 0.6) -> pixel (1, 1), error |(1,3.5)-(1,1)| = 2.5, occluded; (2, 1) has
  // no ground truth; (7, 0) lies outside. Scored 2: EPE 1.25, WAUC (1 + 0.25) / 2 = 62.5 (all);
  // EPE 0, WAUC 100 (noc, 1 vector).
  std::vector<float> gt_sparse(3 * 2 * 2, 1.0f);
  gt_sparse[2 * 5] = gt_sparse[2 * 5 + 1] = kNaNf;
  std::vector<uint8_t> vis_sparse(6, 255);
  vis_sparse[4] = 0;
  const size_t scored = e.addSparseFlow("day", gt_sparse.data(), vis_sparse.data(), 3, 2,
                                        {{0, 0, 1, 1}, {1.4, 0.6, 1, 3.5}, {2, 1, 0, 0}, {7, 0, 1, 1}});
  EXPECT_EQ(scored, 2u);

  // Odometry, day: ground truth at x = 0, 1, 2, 3 m, estimate 1.25 times as far. Segments (every
  // frame starts one; a segment ends at the first frame strictly farther than its length):
  // 0 -> 2 (1 m): error |2.5 - 2| / 1 = 50 %; 0 -> 3 (2 m): 0.75 / 2 = 37.5 %; 1 -> 3 (1 m): 50 %.
  // Mean (50 + 37.5 + 50) / 3. Rain: two poses 0.5 m apart: no segment.
  for (int i = 0; i < 4; ++i) e.addPose("day", 10 + i, at(i), at(1.25 * i));
  e.addPose("rain", 20, at(0), at(0));
  e.addPose("rain", 21, at(0.5), at(0.5));
  return e;
}

TEST(CsvNumber, ShortestRoundTrip) {
  EXPECT_EQ(csvNumber(100.0), "100");
  EXPECT_EQ(csvNumber(0.5), "0.5");
  EXPECT_EQ(csvNumber(62.5), "62.5");
  EXPECT_EQ(csvNumber(2.0 / 3.0), "0.6666666666666666");
  EXPECT_EQ(csvNumber(-1.25), "-1.25");
  EXPECT_EQ(csvNumber(std::nan("")), "");
}

TEST(Evaluation, WorkedExampleNumbers) {
  const EvaluationSummary s = example().summarize();
  ASSERT_EQ(s.conditions.size(), 2u);
  EXPECT_EQ(s.conditions[0].condition, "day") << "the paper's order: day before rain";
  EXPECT_EQ(s.conditions[1].condition, "rain");
  const ConditionSummary &day = s.conditions[0], &rain = s.conditions[1], &all = s.all;

  EXPECT_DOUBLE_EQ(perClass(day, "semantic", "iou_percent")[kRoad], 75.0);
  EXPECT_DOUBLE_EQ(perClass(day, "semantic", "iou_percent")[kCar], 50.0);
  EXPECT_DOUBLE_EQ(perClass(day, "semantic", "iou_percent")[kTree], 0.0);
  EXPECT_TRUE(std::isnan(perClass(day, "semantic", "iou_percent")[2]));
  EXPECT_DOUBLE_EQ(value(day, "semantic", "mean_iou"), 125.0 / 3);
  EXPECT_DOUBLE_EQ(value(rain, "semantic", "mean_iou"), 100.0);
  EXPECT_DOUBLE_EQ(perClass(all, "semantic", "iou_percent")[kRoad], 100.0 * (5.0 / 6));
  EXPECT_DOUBLE_EQ(perClass(all, "semantic", "iou_percent")[kCar], 100.0 * (4.0 / 6));
  EXPECT_DOUBLE_EQ(value(all, "semantic", "mean_iou"), (100.0 * (5.0 / 6) + 100.0 * (4.0 / 6) + 0.0) / 3);
  EXPECT_EQ(count(day, "semantic", "pixels"), 7u);
  EXPECT_EQ(all.scoresOf("semantic").frames, 2u);

  EXPECT_DOUBLE_EQ(perClass(day, "instances", "ap_percent")[kCar], 100.0);
  EXPECT_DOUBLE_EQ(perClass(day, "instances", "ap_percent")[kBus], 50.0);
  EXPECT_DOUBLE_EQ(perClass(day, "instances", "ap50_percent")[kBus], 100.0);
  EXPECT_DOUBLE_EQ(value(day, "instances", "ap"), 75.0);
  EXPECT_DOUBLE_EQ(value(day, "instances", "ap50"), 100.0);
  EXPECT_DOUBLE_EQ(value(rain, "instances", "ap"), 0.0);
  EXPECT_TRUE(std::isnan(perClass(rain, "instances", "ap_percent")[kBus]));
  EXPECT_DOUBLE_EQ(perClass(all, "instances", "ap_percent")[kCar], 50.0);
  EXPECT_DOUBLE_EQ(value(all, "instances", "ap"), 50.0);
  EXPECT_DOUBLE_EQ(value(all, "instances", "ap50"), 75.0);

  EXPECT_EQ(count(day, "flow", "pixels"), 3u);
  EXPECT_NEAR(value(day, "flow", "epe_px"), 12.5 / 3, 1e-12);
  EXPECT_NEAR(value(day, "flow", "wauc"), 100.0 * 1.25 / 3, 1e-12);
  EXPECT_NEAR(value(day, "flow", "outlier_percent"), 100.0 / 3, 1e-12);
  EXPECT_EQ(count(day, "flow", "noc_pixels"), 2u);
  EXPECT_DOUBLE_EQ(value(day, "flow", "noc_epe_px"), 1.25);
  EXPECT_DOUBLE_EQ(value(day, "flow", "noc_wauc"), 62.5);
  EXPECT_DOUBLE_EQ(value(day, "flow", "noc_outlier_percent"), 0.0);
  EXPECT_EQ(rain.scoresOf("flow").frames, 0u);
  EXPECT_EQ(count(all, "flow", "pixels"), 3u);
  EXPECT_EQ(all.scoresOf("flow").frames, 1u);
  // Inlier curve: error 0 counts from 0.05 px on, 2.5 px from 2.55 px on, 10 px never.
  ASSERT_EQ(layoutOf(s, "flow").curve_files.at(0).x.size(), 101u);
  EXPECT_DOUBLE_EQ(curve(day, "flow", "inliers")[0], 0.0);
  EXPECT_NEAR(curve(day, "flow", "inliers")[1], 100.0 / 3, 1e-12);
  EXPECT_NEAR(curve(day, "flow", "inliers")[50], 100.0 / 3, 1e-12);
  EXPECT_NEAR(curve(day, "flow", "inliers")[51], 200.0 / 3, 1e-12);
  EXPECT_NEAR(curve(day, "flow", "inliers")[100], 200.0 / 3, 1e-12);

  EXPECT_EQ(count(day, "flow_sparse", "vectors"), 4u);
  EXPECT_EQ(count(day, "flow_sparse", "pixels"), 2u);
  EXPECT_DOUBLE_EQ(value(day, "flow_sparse", "epe_px"), 1.25);
  EXPECT_DOUBLE_EQ(value(day, "flow_sparse", "wauc"), 62.5);
  EXPECT_DOUBLE_EQ(value(day, "flow_sparse", "outlier_percent"), 0.0);
  EXPECT_EQ(count(day, "flow_sparse", "noc_pixels"), 1u);
  EXPECT_DOUBLE_EQ(value(day, "flow_sparse", "noc_epe_px"), 0.0);
  EXPECT_DOUBLE_EQ(value(day, "flow_sparse", "noc_wauc"), 100.0);

  EXPECT_EQ(day.scoresOf("odometry").frames, 4u);
  EXPECT_EQ(count(day, "odometry", "segments"), 3u);
  EXPECT_DOUBLE_EQ(value(day, "odometry", "translation_percent"), (50.0 + 37.5 + 50.0) / 3);
  EXPECT_DOUBLE_EQ(value(day, "odometry", "rotation_deg_per_m"), 0.0);
  EXPECT_EQ(count(rain, "odometry", "segments"), 0u);
  EXPECT_TRUE(std::isnan(value(rain, "odometry", "translation_percent")));
  EXPECT_EQ(all.scoresOf("odometry").frames, 6u);
  EXPECT_EQ(count(all, "odometry", "sequences"), 2u);
  EXPECT_DOUBLE_EQ(value(all, "odometry", "path_m"), 3.5);
  EXPECT_EQ(count(all, "odometry", "segments"), 3u);
}

TEST(EvalReport, SummaryCsv) {
  const std::string csv = summaryCsv(example().summarize());
  const auto l = lines(csv);
  ASSERT_EQ(l.size(), 4u) << csv;
  EXPECT_EQ(l[0].substr(0, 49), "condition,semantic_frames,mean_iou,instance_frame");
  const std::string third = csvNumber(100.0 / 3);
  EXPECT_EQ(l[1], "day,1," + csvNumber(100.0 * ((0.75 + 0.5 + 0.0) / 3)) + ",1,75,100,1," + csvNumber(100.0 * 1.25 / 3) + "," + csvNumber(12.5 / 3) + "," + third +
                      ",62.5,1.25,0,1,4,62.5,1.25,0,100,0,0,4,3,3," + csvNumber((50.0 + 37.5 + 50.0) / 3) + ",0");
  EXPECT_EQ(l[2], "rain,1,100,1,0,0,0,,,,,,,0,0,,,,,,,2,0.5,0,,");
  EXPECT_EQ(l[3].substr(0, 4), "all,");
}

TEST(EvalReport, PerClassCsv) {
  const EvaluationSummary s = example().summarize();
  const std::string sem = tableCsv(s, "semantic_iou.csv");
  EXPECT_EQ(lines(sem)[0], "condition,class_id,class_name,iou_percent");
  EXPECT_TRUE(hasLine(sem, "day,3,road,75")) << sem;
  EXPECT_TRUE(hasLine(sem, "day,7,tree,0")) << sem;
  EXPECT_TRUE(hasLine(sem, "day,24,car,50")) << sem;
  EXPECT_TRUE(hasLine(sem, "day,-1,mean," + csvNumber(100.0 * ((0.75 + 0.5 + 0.0) / 3)))) << sem;
  EXPECT_TRUE(hasLine(sem, "rain,-1,mean,100")) << sem;
  EXPECT_TRUE(hasLine(sem, "all,3,road," + csvNumber(100.0 * (5.0 / 6)))) << sem;
  EXPECT_FALSE(sem.find(",sky,") != std::string::npos) << "sky has nothing to score";
  const std::string ap = tableCsv(s, "instance_ap.csv");
  EXPECT_EQ(lines(ap)[0], "condition,class_id,class_name,ap_percent,ap50_percent");
  EXPECT_TRUE(hasLine(ap, "day,24,car,100,100")) << ap;
  EXPECT_TRUE(hasLine(ap, "day,26,bus,50,100")) << ap;
  EXPECT_TRUE(hasLine(ap, "day,-1,mean,75,100")) << ap;
  EXPECT_TRUE(hasLine(ap, "rain,24,car,0,0")) << ap;
  EXPECT_TRUE(hasLine(ap, "all,24,car,50,50")) << ap;
  EXPECT_TRUE(hasLine(ap, "all,-1,mean,50,75")) << ap;
  EXPECT_FALSE(hasLine(ap, "rain,26,bus,,")) << "no bus in rain: no row";
}

TEST(EvalReport, FlowAndOdometryCsv) {
  const EvaluationSummary s = example().summarize();
  const std::string flow = tableCsv(s, "flow.csv");
  const std::string third = csvNumber(100.0 / 3);
  EXPECT_EQ(lines(flow).size(), 9u) << flow;  // header + day and all x dense/sparse x all/noc
  EXPECT_TRUE(hasLine(flow, "day,dense,all,1,3,0," + csvNumber(100.0 * 1.25 / 3) + "," + csvNumber(12.5 / 3) + "," +
                                third))
      << flow;
  EXPECT_TRUE(hasLine(flow, "day,dense,noc,1,2,0,62.5,1.25,0")) << flow;
  EXPECT_TRUE(hasLine(flow, "day,sparse,all,1,2,0,62.5,1.25,0")) << flow;
  EXPECT_TRUE(hasLine(flow, "all,sparse,noc,1,1,0,100,0,0")) << flow;

  const std::string inliers = tableCsv(s, "flow_inliers.csv");
  const auto il = lines(inliers);
  ASSERT_EQ(il.size(), 102u);
  EXPECT_EQ(il[0], "threshold_px,day/dense/all,day/dense/noc,day/sparse/all,day/sparse/noc,all/dense/all,"
                   "all/dense/noc,all/sparse/all,all/sparse/noc");
  EXPECT_EQ(il[1], "0,0,0,0,0,0,0,0,0");
  EXPECT_EQ(il[101], "5," + csvNumber(200.0 / 3) + ",100,100,100," + csvNumber(200.0 / 3) + ",100,100,100");

  const std::string odo = tableCsv(s, "odometry.csv");
  EXPECT_EQ(lines(odo)[0], "condition,length_m,segments,translation_percent,rotation_deg_per_m");
  EXPECT_TRUE(hasLine(odo, "day,1,2,50,0")) << odo;
  EXPECT_TRUE(hasLine(odo, "day,2,1,37.5,0")) << odo;
  EXPECT_TRUE(hasLine(odo, "day,all,3," + csvNumber((50.0 + 37.5 + 50.0) / 3) + ",0")) << odo;
  EXPECT_TRUE(hasLine(odo, "rain,1,0,,")) << odo;
  EXPECT_TRUE(hasLine(odo, "rain,all,0,,")) << odo;
}

TEST(EvalReport, Markdown) {
  const std::string md = reportMarkdown(example().summarize());
  EXPECT_TRUE(hasLine(md, "Frames scored: semantic 2, instances 2, dense flow 1, sparse flow 1, odometry poses 6."))
      << md;
  EXPECT_TRUE(hasLine(md, "| condition | mIoU % | AP % | AP50 % | flow EPE px | flow WAUC % | flow Fl % | "
                          "sparse EPE px | sparse WAUC % | VO translation % | VO rotation deg/m |"))
      << md;
  EXPECT_TRUE(hasLine(md, "| day | 41.67 | 75.00 | 100.00 | 4.167 | 41.67 | 33.33 | 1.250 | 62.50 | 45.83 | 0.0000 |"))
      << md;
  EXPECT_TRUE(hasLine(md, "| rain | 100.00 | 0.00 | 0.00 | - | - | - | - | - | - | - |")) << md;
  EXPECT_TRUE(hasLine(md, "| **all** | 50.00 | 50.00 | 75.00 | 4.167 | 41.67 | 33.33 | 1.250 | 62.50 | 45.83 | 0.0000 |"))
      << md;
  // Per-class IoU: rows for scored classes present anywhere, then the mean.
  EXPECT_TRUE(hasLine(md, "| class | day | rain | all |")) << md;
  EXPECT_TRUE(hasLine(md, "| road | 75.00 | 100.00 | 83.33 |")) << md;
  EXPECT_TRUE(hasLine(md, "| tree | 0.00 | - | 0.00 |")) << md;
  EXPECT_TRUE(hasLine(md, "| **mean** | **41.67** | **100.00** | **50.00** |")) << md;
  EXPECT_TRUE(hasLine(md, "| bus | 50.00 | - | 50.00 |")) << md;
  EXPECT_TRUE(hasLine(md, "| day | dense | noc | 1 | 2 | 62.50 | 1.250 | 0.00 | 0 |")) << md;
  EXPECT_TRUE(hasLine(md, "| **all** | sparse | all | 1 | 2 | 62.50 | 1.250 | 0.00 | 0 |")) << md;
  EXPECT_TRUE(hasLine(md, "| rain | 2 | 1 | 0.5 | 0 | - | - |")) << md;
  EXPECT_TRUE(hasLine(md, "| day | 2 | 1 | 37.50 | 0.0000 |")) << md;
  EXPECT_TRUE(hasLine(md, "![flow inlier rate over threshold](flow_inliers.png)")) << md;
  EXPECT_TRUE(hasLine(md, "![VO error over segment length](odometry_errors.png)")) << md;
}

TEST(EvalReport, ScoresYaml) {
  const std::string y = scoresYaml(example().summarize());
  EXPECT_EQ(lines(y)[0], "all:");
  EXPECT_TRUE(hasLine(y, "  semantic: {frames: 2, mean_iou: 50}")) << y;
  EXPECT_TRUE(hasLine(y, "  instances: {frames: 2, ap: 50, ap50: 75}")) << y;
  EXPECT_TRUE(hasLine(y, "  \"rain\":")) << y;
  EXPECT_TRUE(hasLine(y, "    odometry: {poses: 2, path_m: 0.5, segments: 0, translation_percent: .nan, "
                         "rotation_deg_per_m: .nan}"))
      << y;
  EXPECT_TRUE(hasLine(y, "    flow_sparse: {frames: 1, pixels: 2, wauc: 62.5, epe_px: 1.25, outlier_percent: 0, "
                         "noc_wauc: 100, noc_epe_px: 0, noc_outlier_percent: 0}"))
      << y;
}

TEST(EvalReport, NothingScored) {
  Evaluation e(classes());
  const EvaluationSummary s = e.summarize();
  EXPECT_TRUE(s.conditions.empty());
  EXPECT_TRUE(hasLine(reportMarkdown(s),
                      "Nothing was scored: no prediction topic delivered a frame that met its ground truth."));
  const auto l = lines(summaryCsv(s));
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[1], "all,0,,0,,,0,,,,,,,0,0,,,,,,,0,0,0,,");
  EXPECT_EQ(lines(tableCsv(s, "flow.csv")).size(), 1u);
  EXPECT_EQ(scoresYaml(s), "all:\nconditions: {}\n");
}

TEST(Evaluation, AllInvalidAndEmptyInputs) {
  Evaluation e(classes());
  // Flow whose ground truth is undefined everywhere: a frame, but no pixel and NaN scores.
  const std::vector<float> gt = {kNaNf, kNaNf, kNaNf, kNaNf}, pred = {0, 0, 0, 0};
  e.addFlow("night", gt.data(), nullptr, pred.data(), 2);
  // A prediction that is NaN where the truth exists: an invalid, outlier pixel, outside the EPE.
  const std::vector<float> gt2 = {1, 1}, pred2 = {kNaNf, 0};
  e.addFlow("night", gt2.data(), nullptr, pred2.data(), 1);
  // Instances with no prediction at all, and no ground truth: nothing to score (NaN).
  const std::vector<int32_t> ids(4, 0);
  const std::vector<uint8_t> cls(4, kRoad);
  e.addInstances("night", ids.data(), cls.data(), 4, {});
  // Sparse flow with no vector.
  e.addSparseFlow("night", gt2.data(), nullptr, 1, 1, {});
  const EvaluationSummary s = e.summarize();
  ASSERT_EQ(s.conditions.size(), 1u);
  const ConditionSummary& n = s.conditions[0];
  EXPECT_EQ(n.scoresOf("flow").frames, 2u);
  EXPECT_EQ(count(n, "flow", "pixels"), 1u);
  EXPECT_EQ(count(n, "flow", "invalid"), 1u);
  EXPECT_TRUE(std::isnan(value(n, "flow", "epe_px")));
  EXPECT_DOUBLE_EQ(value(n, "flow", "outlier_percent"), 100.0);
  EXPECT_DOUBLE_EQ(value(n, "flow", "wauc"), 0.0);
  EXPECT_EQ(n.scoresOf("instances").frames, 1u);
  EXPECT_TRUE(std::isnan(value(n, "instances", "ap")));
  EXPECT_EQ(n.scoresOf("flow_sparse").frames, 1u);
  EXPECT_EQ(count(n, "flow_sparse", "pixels"), 0u);
  EXPECT_TRUE(hasLine(reportMarkdown(s), "| night | - | - | - | 0.00 | 100.00 | - | - |")) << reportMarkdown(s);
}

TEST(Evaluation, TrajectoryBreaksOnConditionChangeAndFrameNumbersGoingBack) {
  Evaluation e(classes(), smallOdometry());
  for (int i = 0; i < 3; ++i) e.addPose("day", i, at(i), at(i));
  for (int i = 0; i < 3; ++i) e.addPose("day", i, at(i), at(i));  // a replay starting over
  e.addPose("snow", 3, at(3), at(3));
  e.addPose("day", 4, at(4), at(4));  // back to day: a new run
  const EvaluationSummary s = e.summarize();
  ASSERT_EQ(s.conditions.size(), 2u);
  EXPECT_EQ(count(s.conditions[0], "odometry", "sequences"), 3u);
  EXPECT_EQ(s.conditions[0].scoresOf("odometry").frames, 7u);
  EXPECT_DOUBLE_EQ(value(s.conditions[0], "odometry", "path_m"), 4.0);
  EXPECT_EQ(count(s.conditions[1], "odometry", "sequences"), 1u);
  // Two runs of 0..2 m each give segments 0->2 (1 m) only: error 0.
  EXPECT_EQ(count(s.all, "odometry", "segments"), 2u);
  EXPECT_DOUBLE_EQ(value(s.all, "odometry", "translation_percent"), 0.0);
}

TEST(Evaluation, RejectsMismatchedMasksAndBadOptions) {
  Evaluation e(classes());
  const std::vector<int32_t> ids(4, 0);
  const std::vector<uint8_t> cls(4, kRoad);
  PredictedInstance p;
  p.class_id = kCar, p.mask.assign(3, 1);
  EXPECT_THROW(e.addInstances("day", ids.data(), cls.data(), 4, {p}), std::invalid_argument);
  EXPECT_EQ(e.framesAdded(), 0u) << "a rejected frame is not counted";
  EvaluationOptions o;
  o.odometry_lengths_m = {100, 0};
  EXPECT_THROW(Evaluation(classes(), o), std::invalid_argument);
  (void)kSidewalk;
}

// The reduced frame (only ground-truth instance and mask pixels) must score exactly as the
// accumulator does on the whole frame, with full-frame masks and with boxed ones.
TEST(Evaluation, BoxedAndFullFrameInstancesScoreAsTheAccumulatorOnTheWholeFrame) {
  const ClassTable table = classes();
  std::vector<bool> void_class(table.size());
  for (size_t c = 0; c < table.size(); ++c) void_class[c] = !table.semanticEvalMask()[c];
  InstanceApAccumulator direct(table.instanceEvalMask(), void_class);
  Evaluation full(table), boxed(table);
  constexpr uint32_t w = 64, h = 48;
  uint32_t seed = 7;
  auto rnd = [&](uint32_t k) { return (seed = seed * 1103515245u + 12345u) / 65536u % k; };
  for (int frame = 0; frame < 6; ++frame) {
    std::vector<int32_t> ids(w * h, 0);
    std::vector<uint8_t> cls(w * h);
    for (auto& c : cls) c = rnd(4) == 0 ? 0 : kRoad;  // some void
    struct Rect {
      uint32_t x0, y0, w, h;
      int c;
    };
    std::vector<Rect> rects;
    for (int k = 1; k <= 5; ++k) {  // rectangles of cars, buses and people, some under 100 px
      const uint32_t bw = 4 + rnd(20), bh = 4 + rnd(16), x0 = rnd(w - bw), y0 = rnd(h - bh);
      const uint8_t c = std::vector<uint8_t>{kCar, kBus, 20}[rnd(3)];
      rects.push_back({x0, y0, bw, bh, c});
      for (uint32_t y = y0; y < y0 + bh; ++y)
        for (uint32_t x = x0; x < x0 + bw; ++x) ids[y * w + x] = k, cls[y * w + x] = c;
    }
    std::vector<PredictedInstance> masks;
    std::vector<std::vector<uint8_t>> box_masks;
    std::vector<BoxedInstance> boxes;
    for (int k = 0; k < 6; ++k) {
      BoxedInstance b;
      b.score = 0.1 * rnd(10);
      if (k < 4) {  // near a ground-truth rectangle (possibly occluded by a later one), its class
        const Rect& r = rects[k];
        b.class_id = r.c;
        b.x0 = r.x0 > 0 ? r.x0 - rnd(2) : 0, b.y0 = r.y0;
        b.width = std::min(r.w + rnd(3), w - b.x0), b.height = r.h;
      } else {  // anywhere, any class
        b.class_id = std::vector<int>{kCar, kBus, 20}[rnd(3)];
        b.width = 3 + rnd(24), b.height = 3 + rnd(18), b.x0 = rnd(w - b.width), b.y0 = rnd(h - b.height);
      }
      box_masks.emplace_back(b.width * b.height);
      for (auto& v : box_masks.back()) v = rnd(12) != 0;
      boxes.push_back(b);
      PredictedInstance p;
      p.class_id = b.class_id, p.score = b.score;
      p.mask.assign(w * h, 0);
      for (uint32_t y = 0; y < b.height; ++y)
        for (uint32_t x = 0; x < b.width; ++x) p.mask[(b.y0 + y) * w + b.x0 + x] = box_masks.back()[y * b.width + x];
      masks.push_back(std::move(p));
    }
    for (size_t k = 0; k < boxes.size(); ++k) boxes[k].mask = box_masks[k].data();
    direct.add(ids.data(), cls.data(), w * h, masks);
    full.addInstances("day", ids.data(), cls.data(), w * h, masks);
    boxed.addInstances("day", ids.data(), cls.data(), w, h, boxes);
  }
  const EvaluationSummary a = full.summarize(), b = boxed.summarize();
  int compared = 0;
  for (int c : {kCar, kBus, 20}) {
    if (std::isnan(direct.classAp(c))) continue;
    ++compared;
    EXPECT_EQ(perClass(a.all, "instances", "ap_percent")[c], 100.0 * direct.classAp(c)) << c;
    EXPECT_EQ(perClass(b.all, "instances", "ap_percent")[c], 100.0 * direct.classAp(c)) << c;
    EXPECT_EQ(perClass(b.all, "instances", "ap50_percent")[c], 100.0 * direct.classAp50(c)) << c;
  }
  EXPECT_GE(compared, 2);
  EXPECT_EQ(value(b.all, "instances", "ap"), 100.0 * direct.meanAp());
  EXPECT_GT(direct.meanAp(), 0.0) << "the random predictions should hit something";
  EXPECT_LT(direct.meanAp(), 1.0);

  BoxedInstance outside;
  outside.width = 5, outside.height = 5, outside.x0 = w - 4;
  std::vector<uint8_t> five(25, 1);
  outside.mask = five.data();
  const std::vector<int32_t> ids(w * h, 0);
  const std::vector<uint8_t> cls(w * h, kRoad);
  EXPECT_THROW(boxed.addInstances("day", ids.data(), cls.data(), w, h, {outside}), std::invalid_argument);
}

TEST(EvalReport, WritesEveryTableAndNamesTheFileItCannotWrite) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "viper_test_eval_report";
  std::filesystem::remove_all(dir);
  const auto written = writeReportTables(example().summarize(), (dir / "nested").string());
  ASSERT_EQ(written.size(), 7u);
  for (const char* name : {"summary.md", "summary.csv", "semantic_iou.csv", "instance_ap.csv", "flow.csv",
                           "flow_inliers.csv", "odometry.csv"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "nested" / name)) << name;
  EXPECT_EQ(readFile(dir / "nested" / "summary.csv"), summaryCsv(example().summarize()));
  // A plain file where the folder should be.
  std::ofstream(dir / "blocker") << "x";
  try {
    writeReportTables(example().summarize(), (dir / "blocker").string());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("blocker"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace viper
