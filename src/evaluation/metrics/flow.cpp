// Metrics "flow" (dense) and "flow_sparse": endpoint error, WAUC, KITTI Fl and inlier curves, on
// every pixel with ground truth ("all") and on those visible in the next frame ("noc").
#include "viper/evaluation/evaluation.h"

#include <cmath>
#include <stdexcept>

namespace viper {
namespace {

struct FlowState {
  FlowErrorAccumulator all, noc;
  uint64_t frames = 0, vectors = 0;
};

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

// Dense and sparse flow differ in what they read and where their numbers go.
class FlowMetric : public Metric {
 public:
  FlowMetric(const MetricContext& c, bool sparse) : thresholds_(c.options.curve_thresholds_px), sparse_(sparse) {}
  std::string name() const override { return sparse_ ? "flow_sparse" : "flow"; }
  MetricInputs inputs() const override { return kGtFlow | (sparse_ ? kPredSparseFlow : kPredFlow); }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }

  uint64_t add(const EvalFrame& f) override { return sparse_ ? addSparse(f) : addDense(f); }

  void summarize(EvaluationSummary& s) const override {
    static const FlowState kNone;
    FlowState all;
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      const FlowState& f = it != by_condition_.end() ? it->second : kNone;
      fill(f, out);
      all.all.merge(f.all), all.noc.merge(f.noc), all.frames += f.frames, all.vectors += f.vectors;
    }
    fill(all, s.all);
  }

 private:
  uint64_t addDense(const EvalFrame& f) {
    FlowState& s = by_condition_[f.condition];
    const uint64_t before = s.all.scoredPixels();
    FlowErrorAccumulator::addBoth(s.all, s.noc, f.gt_flow, f.pred_flow, f.gt_flow_visible, f.pixels());
    ++s.frames;
    ++frames_;
    return s.all.scoredPixels() - before;
  }

  uint64_t addSparse(const EvalFrame& f) {
    if (f.gt_flow == nullptr) throw std::invalid_argument("Evaluation::addSparseFlow: null ground truth");
    static const std::vector<SparseFlowVector> kNone;
    const std::vector<SparseFlowVector>& flow = f.pred_sparse_flow ? *f.pred_sparse_flow : kNone;
    std::vector<float> gt, pred;
    std::vector<uint8_t> vis;
    gt.reserve(2 * flow.size()), pred.reserve(2 * flow.size()), vis.reserve(flow.size());
    for (const SparseFlowVector& v : flow) {
      const double px = std::round(v.x), py = std::round(v.y);
      if (!(px >= 0.0 && py >= 0.0 && px < f.width && py < f.height)) continue;
      const size_t i = static_cast<size_t>(py) * f.width + static_cast<size_t>(px);
      gt.push_back(f.gt_flow[2 * i]), gt.push_back(f.gt_flow[2 * i + 1]);
      pred.push_back(static_cast<float>(v.u)), pred.push_back(static_cast<float>(v.v));
      vis.push_back(f.gt_flow_visible == nullptr ? 1 : f.gt_flow_visible[i]);
    }
    FlowState& s = by_condition_[f.condition];
    const uint64_t before = s.all.scoredPixels();
    FlowErrorAccumulator::addBoth(s.all, s.noc, gt.data(), pred.data(), vis.data(), vis.size());
    s.vectors += flow.size();
    ++s.frames;
    ++frames_;
    return s.all.scoredPixels() - before;
  }

  void fill(const FlowState& f, ConditionSummary& out) const {
    (sparse_ ? out.sparse_all : out.flow_all) = summarizeFlow(f.all, f.frames, thresholds_);
    (sparse_ ? out.sparse_noc : out.flow_noc) = summarizeFlow(f.noc, f.frames, thresholds_);
    if (sparse_) out.sparse_vectors = f.vectors;
  }

  std::vector<double> thresholds_;
  bool sparse_;
  std::map<std::string, FlowState> by_condition_;
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeDenseFlowMetric(const MetricContext& c) { return std::make_unique<FlowMetric>(c, false); }
std::unique_ptr<Metric> makeSparseFlowMetric(const MetricContext& c) { return std::make_unique<FlowMetric>(c, true); }

}  // namespace viper
