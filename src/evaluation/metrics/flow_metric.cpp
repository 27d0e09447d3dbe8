// Metrics "flow" (dense) and "flow_sparse": endpoint error, WAUC, KITTI Fl and inlier curves, on
// every pixel with ground truth ("all") and on those visible in the next frame ("noc").
#include "viper/evaluation/evaluation.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace viper {
namespace {

struct FlowState {
  explicit FlowState(WaucMode mode) : all(mode), noc(mode) {}
  FlowErrorAccumulator all, noc;
  uint64_t frames = 0, vectors = 0;
};

// Values of one region ("" all, "noc_"): pixels, invalid, wauc, epe_px, outlier_percent; its row
// of the "flow" row set and its inlier curve.
void summarizeRegion(const FlowErrorAccumulator& acc, uint64_t frames, const std::vector<double>& thresholds,
                     const char* input, const std::string& region, MetricScores& out) {
  const std::string prefix = region == "all" ? "" : region + "_";
  ReportRow row;
  row.text = {{"input", input}, {"region", region}};
  row.values = {{"frames", static_cast<double>(frames)},
                {"pixels", static_cast<double>(acc.scoredPixels())},
                {"invalid", static_cast<double>(acc.invalidPredictions())},
                {"wauc", acc.wauc()},
                {"epe_px", acc.averageEndpointError()},
                {"outlier_percent", acc.outlierPercent()}};
  for (const auto& [key, value] : row.values)
    if (key != "frames") out.values[prefix + key] = value;
  out.rows["flow"].push_back(row);
  std::vector<double>& curve = out.curves[prefix + "inliers"];
  for (double t : thresholds) curve.push_back(acc.inlierPercent(t));
}

// Both flow metrics' report: one section and one set of files (group "flow").
MetricLayout flowLayout(bool sparse, const std::vector<double>& thresholds) {
  const std::string input = sparse ? "sparse" : "dense", name = sparse ? "sparse" : "flow", col = name + "_";
  MetricLayout l;
  l.key = sparse ? "flow_sparse" : "flow";
  l.group = "flow";
  l.frames_label = input + " flow";
  l.summary = {{"epe_px", name + " EPE px", 3}, {"wauc", name + " WAUC %", 2}};
  if (!sparse) l.summary.push_back({"outlier_percent", "flow Fl %", 2});
  const int n = ReportColumn::kCount;
  l.summary_csv = {{"frames", col + "frames", n}};
  if (sparse) l.summary_csv.push_back({"vectors", "sparse_vectors", n});
  for (const char* region : {"", "noc_"})
    for (const char* key : {"wauc", "epe_px", "outlier_percent"})
      l.summary_csv.push_back({std::string(region) + key, col + region + key});
  l.yaml = {{"frames", "frames", n}, {"pixels", "pixels", n}};
  for (const char* region : {"", "noc_"})
    for (const char* key : {"wauc", "epe_px", "outlier_percent"})
      l.yaml.push_back({std::string(region) + key, std::string(region) + key});
  l.markdown = {{MarkdownPart::kText,
                 "## Optical flow\n\n`all`: every pixel with ground-truth flow; `noc`: those visible in the next "
                 "frame. Fl: endpoint error > 3 px and > 5 % of the true motion (KITTI). Sparse: one pixel per flow "
                 "vector.\n\n"},
                {MarkdownPart::kTable, "flow"},
                {MarkdownPart::kText, "\n![flow inlier rate over threshold](flow_inliers.png)\n\n"}};
  ReportTable md, csv;
  md.kind = csv.kind = ReportTable::kRows;
  md.name = "flow", md.rows = csv.rows = {"flow"}, md.left_aligned = 3;
  md.columns = {{"input", "input"},          {"region", "region"},    {"frames", "frames", n},
                {"pixels", "pixels", n},     {"wauc", "WAUC %", 2},   {"epe_px", "EPE px", 3},
                {"outlier_percent", "Fl %", 2}, {"invalid", "invalid", n}};
  csv.name = "flow_csv", csv.file = "flow.csv", csv.always = true;
  csv.columns = {{"input", "input"},   {"region", "region"}, {"frames", "frames", n},
                 {"pixels", "pixels", n}, {"invalid", "invalid", n}, {"wauc", "wauc"},
                 {"epe_px", "epe_px"},    {"outlier_percent", "outlier_percent"}};
  l.tables = {md, csv};
  l.curve_files = {{"flow_inliers.csv", "threshold_px", thresholds,
                    {{"inliers", input + "/all"}, {"noc_inliers", input + "/noc"}}}};
  PlotLayout plot;
  plot.file = "flow_inliers.png";
  PlotLayout::Panel panel;
  panel.axes.title = "Optical flow: pixels within an endpoint error";
  panel.axes.x_label = "endpoint error threshold (px)";
  panel.axes.y_label = "inliers (%)";
  panel.axes.x_min = 0.0, panel.axes.x_max = 5.0, panel.axes.y_min = 0.0, panel.axes.y_max = 100.0;
  panel.axes.legend_bottom = true;  // the curves rise towards the top right
  panel.x = thresholds;
  panel.curves = {{"inliers", input}};
  plot.panels = {panel};
  l.plots = {plot};
  return l;
}

// Dense and sparse flow differ in what they read and where their numbers go.
class FlowMetric : public Metric {
 public:
  FlowMetric(const MetricContext& c, bool sparse)
      : thresholds_(c.options.curve_thresholds_px),
        sparse_(sparse),
        fill_missing_(c.options.flow_fill_missing),
        wauc_mode_(c.options.flow_wauc),
        layout_(flowLayout(sparse, thresholds_)) {}
  std::string name() const override { return layout_.key; }
  const MetricLayout& layout() const override { return layout_; }
  MetricInputs inputs() const override { return kGtFlow | (sparse_ ? kPredSparseFlow : kPredFlow); }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }

  uint64_t add(const EvalFrame& f) override { return sparse_ ? addSparse(f) : addDense(f); }

  void summarize(EvaluationSummary& s) const override {
    const FlowState none(wauc_mode_);
    FlowState all(wauc_mode_);
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      const FlowState& f = it != by_condition_.end() ? it->second : none;
      fill(f, out);
      all.all.merge(f.all), all.noc.merge(f.noc), all.frames += f.frames, all.vectors += f.vectors;
    }
    fill(all, s.all);
  }

 private:
  uint64_t addDense(const EvalFrame& f) {
    FlowState& s = by_condition_.try_emplace(f.condition, wauc_mode_).first->second;
    const uint64_t before = s.all.scoredPixels();
    const float* pred = f.pred_flow;
    std::vector<float> filled;
    if (fill_missing_ && pred != nullptr) {
      filled.assign(pred, pred + 2 * f.pixels());
      fillMissingFlow(filled.data(), f.width, f.height);
      pred = filled.data();
    }
    FlowErrorAccumulator::addBoth(s.all, s.noc, f.gt_flow, pred, f.gt_flow_visible, f.pixels());
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
    FlowState& s = by_condition_.try_emplace(f.condition, wauc_mode_).first->second;
    const uint64_t before = s.all.scoredPixels();
    FlowErrorAccumulator::addBoth(s.all, s.noc, gt.data(), pred.data(), vis.data(), vis.size());
    s.vectors += flow.size();
    ++s.frames;
    ++frames_;
    return s.all.scoredPixels() - before;
  }

  void fill(const FlowState& f, ConditionSummary& out) const {
    MetricScores& scores = out.scores[name()];
    scores.frames = f.frames;
    const char* input = sparse_ ? "sparse" : "dense";
    summarizeRegion(f.all, f.frames, thresholds_, input, "all", scores);
    summarizeRegion(f.noc, f.frames, thresholds_, input, "noc", scores);
    if (sparse_) scores.values["vectors"] = static_cast<double>(f.vectors);
  }

  std::vector<double> thresholds_;
  bool sparse_, fill_missing_;
  WaucMode wauc_mode_;
  MetricLayout layout_;
  std::map<std::string, FlowState> by_condition_;
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeDenseFlowMetric(const MetricContext& c) { return std::make_unique<FlowMetric>(c, false); }
std::unique_ptr<Metric> makeSparseFlowMetric(const MetricContext& c) { return std::make_unique<FlowMetric>(c, true); }

}  // namespace viper
