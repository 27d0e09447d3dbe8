#include "viper/evaluation/evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viper {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// The paper's order of the conditions; others follow by name.
int conditionRank(const std::string& c) {
  static const std::vector<std::string> order = {"day", "sunset", "rain", "snow", "night"};
  const auto it = std::find(order.begin(), order.end(), c);
  return it == order.end() ? static_cast<int>(order.size()) : static_cast<int>(it - order.begin());
}

FlowSummary summarizeFlow(const FlowErrorAccumulator& acc, uint64_t frames, const std::vector<double>& thresholds) {
  FlowSummary s;
  s.frames = frames;
  s.pixels = acc.scoredPixels();
  s.invalid = acc.invalidPredictions();
  s.wauc = acc.wauc();
  s.epe_px = acc.averageEndpointError();
  s.outlier_percent = acc.outlierPercent();
  for (double t : thresholds) s.inlier_percent.push_back(acc.inlierPercent(t));
  return s;
}

}  // namespace

std::vector<double> EvaluationOptions::defaultCurveThresholds() {
  std::vector<double> t;
  for (int i = 0; i <= 100; ++i) t.push_back(0.05 * i);
  return t;
}

Evaluation::Evaluation(const ClassTable& classes, EvaluationOptions options)
    : classes_(classes),
      options_(std::move(options)),
      semantic_eval_(classes.semanticEvalMask()),
      instance_eval_(classes.instanceEvalMask()) {
  if (classes_.size() == 0) throw std::invalid_argument("Evaluation: empty class table");
  if (options_.odometry_step_frames == 0) throw std::invalid_argument("Evaluation: odometry_step_frames must be > 0");
  for (double len : options_.odometry_lengths_m)
    if (!(len > 0.0)) throw std::invalid_argument("Evaluation: odometry segment lengths must be > 0");
  void_class_.resize(semantic_eval_.size());
  for (size_t c = 0; c < semantic_eval_.size(); ++c) void_class_[c] = !semantic_eval_[c];
}

uint64_t Evaluation::framesAdded() const {
  return semantic_frames_ + instance_frames_ + flow_frames_ + sparse_frames_ + poses_;
}

void Evaluation::addSemantic(const std::string& condition, const uint8_t* gt, const uint8_t* pred, size_t n) {
  auto it = semantic_.find(condition);
  if (it == semantic_.end())
    it = semantic_.emplace(condition, std::make_pair(SemanticConfusion(semantic_eval_), uint64_t{0})).first;
  it->second.first.add(gt, pred, n);
  ++it->second.second;
  ++semantic_frames_;
}

void Evaluation::addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                              size_t n, const std::vector<PredictedInstance>& predictions) {
  for (size_t p = 0; p < predictions.size(); ++p)
    if (predictions[p].mask.size() != n)
      throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " mask has " +
                                  std::to_string(predictions[p].mask.size()) + " pixels, frame has " +
                                  std::to_string(n));
  if (n >= std::numeric_limits<uint32_t>::max()) throw std::invalid_argument("Evaluation::addInstances: frame too large");
  // A full-frame mask is a box of one row of n pixels.
  std::vector<BoxedInstance> boxed(predictions.size());
  for (size_t p = 0; p < predictions.size(); ++p) {
    boxed[p].class_id = predictions[p].class_id;
    boxed[p].score = predictions[p].score;
    boxed[p].width = static_cast<uint32_t>(n), boxed[p].height = n > 0 ? 1 : 0;
    boxed[p].mask = predictions[p].mask.data();
  }
  addInstanceOverlaps(condition, gt_ids, gt_classes, static_cast<uint32_t>(n), n > 0 ? 1 : 0, boxed);
}

void Evaluation::addInstances(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                              uint32_t width, uint32_t height, const std::vector<BoxedInstance>& predictions) {
  for (size_t p = 0; p < predictions.size(); ++p) {
    const BoxedInstance& b = predictions[p];
    if (static_cast<uint64_t>(b.x0) + b.width > width || static_cast<uint64_t>(b.y0) + b.height > height)
      throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " box " +
                                  std::to_string(b.width) + "x" + std::to_string(b.height) + " at (" +
                                  std::to_string(b.x0) + ", " + std::to_string(b.y0) + ") leaves the " +
                                  std::to_string(width) + "x" + std::to_string(height) + " frame");
    if (b.mask == nullptr && b.width > 0 && b.height > 0)
      throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " has no mask");
  }
  addInstanceOverlaps(condition, gt_ids, gt_classes, width, height, predictions);
}

// The overlaps are counted once and added to both accumulators.
void Evaluation::addInstanceOverlaps(const std::string& condition, const int32_t* gt_ids, const uint8_t* gt_classes,
                                     uint32_t width, uint32_t height, const std::vector<BoxedInstance>& predictions) {
  if (static_cast<size_t>(width) * height > 0 && (gt_ids == nullptr || gt_classes == nullptr))
    throw std::invalid_argument("Evaluation::addInstances: null ground truth image");
  auto it = instances_.find(condition);
  if (it == instances_.end())
    it = instances_
             .emplace(condition, std::make_pair(InstanceApAccumulator(instance_eval_, void_class_,
                                                                      options_.min_instance_px),
                                                uint64_t{0}))
             .first;
  if (!all_instances_) all_instances_.emplace(instance_eval_, void_class_, options_.min_instance_px);
  const InstanceOverlaps frame = it->second.first.overlaps(gt_ids, gt_classes, width, height, predictions);
  it->second.first.add(frame);
  all_instances_->add(frame);
  ++it->second.second;
  ++instance_frames_;
}

void Evaluation::addFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible,
                         const float* pred_uv, size_t n) {
  FlowState& f = flow_[condition];
  FlowErrorAccumulator::addBoth(f.all, f.noc, gt_uv, pred_uv, visible, n);
  ++f.frames;
  ++flow_frames_;
}

size_t Evaluation::addSparseFlow(const std::string& condition, const float* gt_uv, const uint8_t* visible,
                                 uint32_t width, uint32_t height, const std::vector<SparseFlowVector>& flow) {
  if (gt_uv == nullptr) throw std::invalid_argument("Evaluation::addSparseFlow: null ground truth");
  std::vector<float> gt, pred;
  std::vector<uint8_t> vis;
  gt.reserve(2 * flow.size()), pred.reserve(2 * flow.size()), vis.reserve(flow.size());
  for (const SparseFlowVector& f : flow) {
    const double px = std::round(f.x), py = std::round(f.y);
    if (!(px >= 0.0 && py >= 0.0 && px < width && py < height)) continue;
    const size_t i = static_cast<size_t>(py) * width + static_cast<size_t>(px);
    gt.push_back(gt_uv[2 * i]), gt.push_back(gt_uv[2 * i + 1]);
    pred.push_back(static_cast<float>(f.u)), pred.push_back(static_cast<float>(f.v));
    vis.push_back(visible == nullptr ? 1 : visible[i]);
  }
  FlowState& s = sparse_[condition];
  const uint64_t before = s.all.scoredPixels();
  FlowErrorAccumulator::addBoth(s.all, s.noc, gt.data(), pred.data(), vis.data(), vis.size());
  s.vectors += flow.size();
  ++s.frames;
  ++sparse_frames_;
  return static_cast<size_t>(s.all.scoredPixels() - before);
}

void Evaluation::addPose(const std::string& condition, uint64_t frame_number, const Eigen::Isometry3d& gt,
                         const Eigen::Isometry3d& estimate) {
  std::vector<Trajectory>& runs = trajectories_[condition];
  const bool continues = !runs.empty() && last_pose_condition_ == condition && frame_number > runs.back().last_frame;
  if (!continues) runs.emplace_back();
  Trajectory& t = runs.back();
  t.gt.push_back(gt);
  t.est.push_back(estimate);
  t.last_frame = frame_number;
  last_pose_condition_ = condition;
  ++poses_;
}

void Evaluation::fillOdometry(const std::vector<const Trajectory*>& trajectories, ConditionSummary& out) const {
  std::vector<SegmentError> errors;
  for (const Trajectory* t : trajectories) {
    out.odometry_poses += t->gt.size();
    for (size_t i = 1; i < t->gt.size(); ++i)
      out.odometry_path_m += (t->gt[i].translation() - t->gt[i - 1].translation()).norm();
    const auto e = kittiSegmentErrors(t->gt, t->est, options_.odometry_lengths_m, options_.odometry_step_frames);
    errors.insert(errors.end(), e.begin(), e.end());
  }
  out.odometry_sequences = trajectories.size();
  out.odometry = summarizeSegments(errors, options_.odometry_lengths_m);
}

EvaluationSummary Evaluation::summarize() const {
  EvaluationSummary s;
  for (const ClassInfo& c : classes_.classes()) s.class_names.push_back(c.name);
  s.semantic_eval = semantic_eval_;
  s.instance_eval = instance_eval_;
  s.curve_thresholds_px = options_.curve_thresholds_px;
  const size_t k = classes_.size();
  const std::vector<double>& th = options_.curve_thresholds_px;

  auto fillSemantic = [&](const SemanticConfusion* sc, ConditionSummary& out) {
    out.iou.assign(k, kNaN);
    out.mean_iou = kNaN;
    if (sc == nullptr) return;
    out.semantic_pixels = sc->scoredPixels();
    out.mean_iou = 100.0 * sc->meanIou();
    for (size_t c = 0; c < k; ++c) out.iou[c] = 100.0 * sc->iou(static_cast<int>(c));
  };
  auto fillInstances = [&](const InstanceApAccumulator* acc, ConditionSummary& out) {
    out.ap = out.ap50 = kNaN;
    out.class_ap.assign(k, kNaN);
    out.class_ap50.assign(k, kNaN);
    if (acc == nullptr) return;
    out.ap = 100.0 * acc->meanAp();
    out.ap50 = 100.0 * acc->meanAp50();
    for (size_t c = 0; c < k; ++c) {
      out.class_ap[c] = 100.0 * acc->classAp(static_cast<int>(c));
      out.class_ap50[c] = 100.0 * acc->classAp50(static_cast<int>(c));
    }
  };

  std::vector<std::string> names;
  auto collect = [&](const auto& by_condition) {
    for (const auto& entry : by_condition)
      if (std::find(names.begin(), names.end(), entry.first) == names.end()) names.push_back(entry.first);
  };
  collect(semantic_), collect(instances_), collect(flow_), collect(sparse_), collect(trajectories_);
  std::sort(names.begin(), names.end());
  std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return conditionRank(a) < conditionRank(b);
  });

  std::optional<SemanticConfusion> all_semantic;
  FlowState all_flow, all_sparse;
  std::vector<const Trajectory*> all_trajectories;
  for (const std::string& name : names) {
    ConditionSummary out;
    out.condition = name;
    const auto sem = semantic_.find(name);
    if (sem != semantic_.end()) {
      out.semantic_frames = sem->second.second;
      if (all_semantic) all_semantic->merge(sem->second.first);
      else all_semantic = sem->second.first;
    }
    fillSemantic(sem != semantic_.end() ? &sem->second.first : nullptr, out);
    const auto inst = instances_.find(name);
    if (inst != instances_.end()) out.instance_frames = inst->second.second;
    fillInstances(inst != instances_.end() ? &inst->second.first : nullptr, out);
    static const FlowState kNone;
    const auto fl = flow_.find(name);
    const FlowState& f = fl != flow_.end() ? fl->second : kNone;
    out.flow_all = summarizeFlow(f.all, f.frames, th);
    out.flow_noc = summarizeFlow(f.noc, f.frames, th);
    all_flow.all.merge(f.all), all_flow.noc.merge(f.noc), all_flow.frames += f.frames;
    const auto sp = sparse_.find(name);
    const FlowState& g = sp != sparse_.end() ? sp->second : kNone;
    out.sparse_all = summarizeFlow(g.all, g.frames, th);
    out.sparse_noc = summarizeFlow(g.noc, g.frames, th);
    out.sparse_vectors = g.vectors;
    all_sparse.all.merge(g.all), all_sparse.noc.merge(g.noc), all_sparse.frames += g.frames;
    all_sparse.vectors += g.vectors;
    std::vector<const Trajectory*> trajectories;
    if (const auto tr = trajectories_.find(name); tr != trajectories_.end())
      for (const Trajectory& t : tr->second) trajectories.push_back(&t);
    fillOdometry(trajectories, out);
    all_trajectories.insert(all_trajectories.end(), trajectories.begin(), trajectories.end());
    s.all.semantic_frames += out.semantic_frames;
    s.all.instance_frames += out.instance_frames;
    s.conditions.push_back(std::move(out));
  }
  ConditionSummary& all = s.all;
  all.condition = "all";
  fillSemantic(all_semantic ? &*all_semantic : nullptr, all);
  fillInstances(all_instances_ ? &*all_instances_ : nullptr, all);
  all.flow_all = summarizeFlow(all_flow.all, all_flow.frames, th);
  all.flow_noc = summarizeFlow(all_flow.noc, all_flow.frames, th);
  all.sparse_all = summarizeFlow(all_sparse.all, all_sparse.frames, th);
  all.sparse_noc = summarizeFlow(all_sparse.noc, all_sparse.frames, th);
  all.sparse_vectors = all_sparse.vectors;
  fillOdometry(all_trajectories, all);
  return s;
}

}  // namespace viper
