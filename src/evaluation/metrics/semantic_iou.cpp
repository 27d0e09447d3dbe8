// Metric "semantic": IoU per evaluated class and their mean (VIPER, Cityscapes).
#include "viper/evaluation/evaluation.h"

#include <limits>
#include <optional>
#include <stdexcept>

namespace viper {
namespace {

class SemanticIouMetric : public Metric {
 public:
  explicit SemanticIouMetric(const MetricContext& c) : evaluated_(c.classes.semanticEvalMask()) {}
  std::string name() const override { return "semantic"; }
  MetricInputs inputs() const override { return kGtSemantic | kPredSemantic; }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }

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
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      if (it == by_condition_.end()) {
        fill(nullptr, out);
        continue;
      }
      out.semantic_frames = it->second.frames;
      s.all.semantic_frames += it->second.frames;
      if (all) all->merge(it->second.acc);
      else all = it->second.acc;
      fill(&it->second.acc, out);
    }
    fill(all ? &*all : nullptr, s.all);
  }

 private:
  void fill(const SemanticConfusion* sc, ConditionSummary& out) const {
    const size_t k = evaluated_.size();
    out.iou.assign(k, std::numeric_limits<double>::quiet_NaN());
    out.mean_iou = std::numeric_limits<double>::quiet_NaN();
    if (sc == nullptr) return;
    out.semantic_pixels = sc->scoredPixels();
    out.mean_iou = 100.0 * sc->meanIou();
    for (size_t c = 0; c < k; ++c) out.iou[c] = 100.0 * sc->iou(static_cast<int>(c));
  }

  std::vector<bool> evaluated_;
  std::map<std::string, Counted<SemanticConfusion>> by_condition_;
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeSemanticIouMetric(const MetricContext& c) {
  return std::make_unique<SemanticIouMetric>(c);
}

}  // namespace viper
