// Metric "instances": Cityscapes instance-segmentation AP over IoU 0.50:0.05:0.95, and at 0.50.
#include "viper/evaluation/evaluation.h"

#include <limits>
#include <optional>
#include <stdexcept>

namespace viper {
namespace {

class InstanceApMetric : public Metric {
 public:
  explicit InstanceApMetric(const MetricContext& c)
      : evaluated_(c.classes.instanceEvalMask()), min_px_(c.options.min_instance_px) {
    for (bool scored : c.classes.semanticEvalMask()) void_class_.push_back(!scored);
    layout_.key = "instances";
    layout_.frames_label = "instances";
    layout_.summary = {{"ap", "AP %", 2}, {"ap50", "AP50 %", 2}};
    layout_.summary_csv = {{"frames", "instance_frames", ReportColumn::kCount}, {"ap", "ap"}, {"ap50", "ap50"}};
    layout_.yaml = {{"frames", "frames", ReportColumn::kCount}, {"ap", "ap"}, {"ap50", "ap50"}};
    layout_.markdown = {
        {MarkdownPart::kText, "## Instance segmentation: AP % per class (IoU 0.50:0.05:0.95, Cityscapes)\n\n"},
        {MarkdownPart::kTable, "ap"},
        {MarkdownPart::kText, "\n## Instance segmentation: AP50 % per class\n\n"},
        {MarkdownPart::kTable, "ap50"},
        {MarkdownPart::kText, "\n"}};
    ReportTable ap, ap50, csv;
    ap.name = "ap", ap.columns = {{"ap_percent", "AP %", 2}}, ap.mean = {{"ap", "AP %", 2}};
    ap50.name = "ap50", ap50.columns = {{"ap50_percent", "AP50 %", 2}}, ap50.mean = {{"ap50", "AP50 %", 2}};
    csv.name = "instance_ap", csv.file = "instance_ap.csv", csv.always = true;
    csv.columns = {ap.columns[0], ap50.columns[0]};
    csv.mean = {ap.mean[0], ap50.mean[0]};
    layout_.tables = {ap, ap50, csv};
    layout_.classes = evaluated_;
  }
  std::string name() const override { return layout_.key; }
  const MetricLayout& layout() const override { return layout_; }
  MetricInputs inputs() const override { return kGtSemantic | kGtInstanceIds | kPredInstances; }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }

  uint64_t add(const EvalFrame& f) override {
    static const std::vector<BoxedInstance> kNone;
    const std::vector<BoxedInstance>& predictions = f.pred_instances ? *f.pred_instances : kNone;
    for (size_t p = 0; p < predictions.size(); ++p) {
      const BoxedInstance& b = predictions[p];
      if (static_cast<uint64_t>(b.x0) + b.width > f.width || static_cast<uint64_t>(b.y0) + b.height > f.height)
        throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " box " +
                                    std::to_string(b.width) + "x" + std::to_string(b.height) + " at (" +
                                    std::to_string(b.x0) + ", " + std::to_string(b.y0) + ") leaves the " +
                                    std::to_string(f.width) + "x" + std::to_string(f.height) + " frame");
      if (b.mask == nullptr && b.width > 0 && b.height > 0)
        throw std::invalid_argument("Evaluation::addInstances: prediction " + std::to_string(p) + " has no mask");
    }
    if (f.pixels() > 0 && (f.gt_instance_ids == nullptr || f.gt_semantic == nullptr))
      throw std::invalid_argument("Evaluation::addInstances: null ground truth image");
    auto it = by_condition_.find(f.condition);
    if (it == by_condition_.end())
      it = by_condition_
               .emplace(f.condition,
                        Counted<InstanceApAccumulator>{InstanceApAccumulator(evaluated_, void_class_, min_px_), 0})
               .first;
    if (!all_) all_.emplace(evaluated_, void_class_, min_px_);
    // The overlaps are counted once and added to both accumulators (AP does not merge).
    const InstanceOverlaps frame =
        it->second.acc.overlaps(f.gt_instance_ids, f.gt_semantic, f.width, f.height, predictions);
    it->second.acc.add(frame);
    all_->add(frame);
    ++it->second.frames;
    ++frames_;
    return f.pixels();
  }

  void summarize(EvaluationSummary& s) const override {
    uint64_t all_frames = 0;
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      const uint64_t frames = it != by_condition_.end() ? it->second.frames : 0;
      all_frames += frames;
      out.scores[name()] = scores(it != by_condition_.end() ? &it->second.acc : nullptr, frames);
    }
    s.all.scores[name()] = scores(all_ ? &*all_ : nullptr, all_frames);
  }

 private:
  // Values: ap, ap50; per class: ap_percent, ap50_percent.
  MetricScores scores(const InstanceApAccumulator* acc, uint64_t frames) const {
    const size_t k = evaluated_.size();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    MetricScores out;
    out.frames = frames;
    out.values["ap"] = out.values["ap50"] = nan;
    std::vector<double>& class_ap = out.per_class["ap_percent"];
    std::vector<double>& class_ap50 = out.per_class["ap50_percent"];
    class_ap.assign(k, nan);
    class_ap50.assign(k, nan);
    if (acc == nullptr) return out;
    out.values["ap"] = 100.0 * acc->meanAp();
    out.values["ap50"] = 100.0 * acc->meanAp50();
    for (size_t c = 0; c < k; ++c) {
      class_ap[c] = 100.0 * acc->classAp(static_cast<int>(c));
      class_ap50[c] = 100.0 * acc->classAp50(static_cast<int>(c));
    }
    return out;
  }

  MetricLayout layout_;
  std::vector<bool> evaluated_, void_class_;
  int min_px_;
  std::map<std::string, Counted<InstanceApAccumulator>> by_condition_;
  std::optional<InstanceApAccumulator> all_;
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeInstanceApMetric(const MetricContext& c) {
  return std::make_unique<InstanceApMetric>(c);
}

}  // namespace viper
