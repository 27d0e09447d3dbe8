// Metric "semantic": IoU per evaluated class and their mean (VIPER, Cityscapes).
#include "viper/evaluation/evaluation.h"

#include <limits>
#include <optional>
#include <stdexcept>

namespace viper {
namespace {

class SemanticIouMetric : public Metric {
 public:
  explicit SemanticIouMetric(const MetricContext& c) : evaluated_(c.classes.semanticEvalMask()) {
    layout_.key = "semantic";
    layout_.frames_label = "semantic";
    layout_.summary = {{"mean_iou", "mIoU %", 2}};
    layout_.summary_csv = {{"frames", "semantic_frames", ReportColumn::kCount}, {"mean_iou", "mean_iou"}};
    layout_.yaml = {{"frames", "frames", ReportColumn::kCount}, {"mean_iou", "mean_iou"}};
    layout_.markdown = {{MarkdownPart::kText, "## Semantic segmentation: IoU % per class\n\n"},
                        {MarkdownPart::kTable, "iou"},
                        {MarkdownPart::kText, "\n"}};
    ReportTable iou;
    iou.name = "iou", iou.file = "semantic_iou.csv", iou.always = true;
    iou.columns = {{"iou_percent", "IoU %", 2}};
    iou.mean = {{"mean_iou", "mIoU %", 2}};
    layout_.tables = {iou};
    layout_.classes = evaluated_;
  }
  std::string name() const override { return layout_.key; }
  MetricInputs inputs() const override { return kGtSemantic | kPredSemantic; }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }
  const MetricLayout& layout() const override { return layout_; }

  uint64_t add(const EvalFrame& f) override {
    auto it = by_condition_.find(f.condition);
    if (it == by_condition_.end())
      it = by_condition_.emplace(f.condition, Counted<SemanticConfusion>{SemanticConfusion(evaluated_), 0}).first;
    const uint64_t before = it->second.acc.scoredPixels();
    it->second.acc.add(f.gt_semantic, f.pred_semantic, f.pixels());
    ++it->second.frames;
    ++frames_;
    return it->second.acc.scoredPixels() - before;
  }

  void summarize(EvaluationSummary& s) const override {
    std::optional<SemanticConfusion> all;
    uint64_t all_frames = 0;
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      if (it == by_condition_.end()) {
        out.scores[name()] = scores(nullptr, 0);
        continue;
      }
      all_frames += it->second.frames;
      if (all) all->merge(it->second.acc);
      else all = it->second.acc;
      out.scores[name()] = scores(&it->second.acc, it->second.frames);
    }
    s.all.scores[name()] = scores(all ? &*all : nullptr, all_frames);
  }

 private:
  // Values: mean_iou, pixels (scored); per class: iou_percent.
  MetricScores scores(const SemanticConfusion* sc, uint64_t frames) const {
    const size_t k = evaluated_.size();
    MetricScores out;
    out.frames = frames;
    std::vector<double>& iou = out.per_class["iou_percent"];
    iou.assign(k, std::numeric_limits<double>::quiet_NaN());
    out.values["mean_iou"] = std::numeric_limits<double>::quiet_NaN();
    out.values["pixels"] = 0.0;
    if (sc == nullptr) return out;
    out.values["pixels"] = static_cast<double>(sc->scoredPixels());
    out.values["mean_iou"] = 100.0 * sc->meanIou();
    for (size_t c = 0; c < k; ++c) iou[c] = 100.0 * sc->iou(static_cast<int>(c));
    return out;
  }

  std::vector<bool> evaluated_;
  MetricLayout layout_;
  std::map<std::string, Counted<SemanticConfusion>> by_condition_;
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeSemanticIouMetric(const MetricContext& c) {
  return std::make_unique<SemanticIouMetric>(c);
}

}  // namespace viper
