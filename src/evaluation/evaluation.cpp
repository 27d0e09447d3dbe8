#include "viper/evaluation/evaluation.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace viper {
namespace {

// The paper's order of the conditions; others follow by name.
int conditionRank(const std::string& c) {
  static const std::vector<std::string> order = {"day", "sunset", "rain", "snow", "night"};
  const auto it = std::find(order.begin(), order.end(), c);
  return it == order.end() ? static_cast<int>(order.size()) : static_cast<int>(it - order.begin());
}

// A frame of n pixels given without its shape: one row.
EvalFrame rowFrame(const std::string& condition, size_t n, const char* what) {
  if (n >= std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument(std::string("Evaluation::") + what + ": frame too large");
  EvalFrame f;
  f.condition = condition;
  f.width = static_cast<uint32_t>(n);
  f.height = n > 0 ? 1 : 0;
  return f;
}

}  // namespace

std::vector<double> EvaluationOptions::defaultCurveThresholds() {
  std::vector<double> t;
  for (int i = 0; i <= 100; ++i) t.push_back(0.05 * i);
  return t;
}

double MetricScores::value(const std::string& key) const {
  if (key == "frames") return static_cast<double>(frames);
  const auto it = values.find(key);
  return it == values.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

const MetricScores& ConditionSummary::scoresOf(const std::string& metric) const {
  static const MetricScores kNone;
  const auto it = scores.find(metric);
  return it == scores.end() ? kNone : it->second;
}

Evaluation::Evaluation(const ClassTable& classes, EvaluationOptions options)
    : classes_(classes), options_(std::move(options)) {
  if (classes_.size() == 0) throw std::invalid_argument("Evaluation: empty class table");
  if (options_.odometry_step_frames == 0) throw std::invalid_argument("Evaluation: odometry_step_frames must be > 0");
  for (double len : options_.odometry_lengths_m)
    if (!(len > 0.0)) throw std::invalid_argument("Evaluation: odometry segment lengths must be > 0");
  const MetricContext context{classes_, options_};
  for (MetricFactory make : registeredMetrics()) metrics_.push_back(make(context));
}

Evaluation::Evaluation(Evaluation&&) noexcept = default;
Evaluation& Evaluation::operator=(Evaluation&&) noexcept = default;
Evaluation::~Evaluation() = default;

Metric* Evaluation::metric(const std::string& name) const {
  for (const auto& m : metrics_)
    if (m->name() == name) return m.get();
  return nullptr;
}

uint64_t Evaluation::add(const std::string& name, const EvalFrame& frame) {
  Metric* m = metric(name);
  if (m == nullptr) throw std::invalid_argument("Evaluation::add: no metric called '" + name + "'");
  return m->add(frame);
}

uint64_t Evaluation::framesAdded() const {
  uint64_t frames = 0;
  for (const auto& m : metrics_) frames += m->frames();
  return frames;
}

void Evaluation::addSemantic(const std::string& condition, const uint8_t* gt, const uint8_t* pred, size_t n) {
  EvalFrame f = rowFrame(condition, n, "addSemantic");
  f.gt_semantic = gt, f.pred_semantic = pred;
  add("semantic", f);
}

void Evaluation::addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                              size_t n, const std::vector<PredictedInstance>& predictions) {
  for (size_t p = 0; p < predictions.size(); ++p)
    if (predictions[p].mask.size() != n)
      throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " mask has " +
                                  std::to_string(predictions[p].mask.size()) + " pixels, frame has " +
                                  std::to_string(n));
  const EvalFrame f = rowFrame(condition, n, "addInstances");
  // A full-frame mask is a box of one row of n pixels.
  std::vector<BoxedInstance> boxed(predictions.size());
  for (size_t p = 0; p < predictions.size(); ++p) {
    boxed[p].class_id = predictions[p].class_id;
    boxed[p].score = predictions[p].score;
    boxed[p].width = f.width, boxed[p].height = f.height;
    boxed[p].mask = predictions[p].mask.data();
  }
  addInstances(condition, gt_ids, gt_classes, f.width, f.height, boxed);
}

void Evaluation::addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                              uint32_t width, uint32_t height, const std::vector<BoxedInstance>& predictions) {
  EvalFrame f;
  f.condition = condition, f.width = width, f.height = height;
  f.gt_instance_ids = gt_ids, f.gt_semantic = gt_classes, f.pred_instances = &predictions;
  add("instances", f);
}

void Evaluation::addFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible,
                         const float* pred_uv, size_t n) {
  EvalFrame f = rowFrame(condition, n, "addFlow");
  f.gt_flow = gt_uv, f.gt_flow_visible = visible, f.pred_flow = pred_uv;
  add("flow", f);
}

size_t Evaluation::addSparseFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible,
                                 uint32_t width, uint32_t height, const std::vector<SparseFlowVector>& flow) {
  EvalFrame f;
  f.condition = condition, f.width = width, f.height = height;
  f.gt_flow = gt_uv, f.gt_flow_visible = visible, f.pred_sparse_flow = &flow;
  return static_cast<size_t>(add("flow_sparse", f));
}

void Evaluation::addPose(const std::string& condition, uint64_t frame_number, const Eigen::Isometry3d& gt,
                         const Eigen::Isometry3d& estimate) {
  EvalFrame f;
  f.condition = condition, f.frame_number = frame_number;
  f.gt_pose = &gt, f.pred_pose = &estimate;
  add("odometry", f);
}

EvaluationSummary Evaluation::summarize() const {
  EvaluationSummary s;
  for (const ClassInfo& c : classes_.classes()) s.class_names.push_back(c.name);
  std::vector<std::string> names;
  for (const auto& m : metrics_) {
    for (const std::string& c : m->conditions())
      if (std::find(names.begin(), names.end(), c) == names.end()) names.push_back(c);
    s.layouts.push_back(m->layout());
  }
  std::sort(names.begin(), names.end());
  std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return conditionRank(a) < conditionRank(b);
  });
  for (const std::string& name : names) {
    s.conditions.emplace_back();
    s.conditions.back().condition = name;
  }
  s.all.condition = "all";
  for (const auto& m : metrics_) m->summarize(s);
  return s;
}

}  // namespace viper
