// Metric "semantic_iiou": Cityscapes' instance-level IoU of the semantic prediction
// (cityscapesScripts evaluation/evalPixelLevelSemanticLabeling.py, getInstanceIouScoreForLabel).
// For an instance class c, each ground-truth instance's true-positive and false-negative pixels
// are weighted by (average instance size of c) / (its size), so that small objects count as much
// as large ones; false positives (pixels predicted c whose scored ground truth is another class)
// are not weighted: iIoU = wTP / (wTP + FP + wFN). Cityscapes takes the average sizes from a fixed
// table of its training set; here they are the average over every ground-truth instance this
// evaluation has seen (all conditions), so wTP = avg * sum(tp / size) is accumulated as the sum.
#include "viper/evaluation/evaluation.h"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

namespace viper {
namespace {

struct ClassCounts {
  double tp_rel = 0.0, fn_rel = 0.0;  // sums of tp / size and fn / size over instances
  uint64_t fp = 0;
  void merge(const ClassCounts& o) { tp_rel += o.tp_rel, fn_rel += o.fn_rel, fp += o.fp; }
};

class SemanticIiouMetric : public Metric {
 public:
  explicit SemanticIiouMetric(const MetricContext& c)
      : scored_(c.classes.semanticEvalMask()), instance_class_(c.classes.instanceEvalMask()) {
    layout_.key = "semantic_iiou";
    layout_.summary = {{"mean_iiou", "iIoU %", 2}};
    layout_.yaml = {{"frames", "frames", ReportColumn::kCount}, {"mean_iiou", "mean_iiou"}};
    layout_.markdown = {
        {MarkdownPart::kText,
         "\n## Semantic segmentation: iIoU % per instance class (Cityscapes)\n\n"
         "Instance-weighted IoU: each ground-truth instance's pixels weigh (average instance size of its class) / "
         "(its size); averages over every instance of this evaluation.\n\n"},
        {MarkdownPart::kTable, "iiou"}};
    ReportTable iiou;
    iiou.name = "iiou", iiou.file = "semantic_iiou.csv";
    iiou.columns = {{"iiou_percent", "iIoU %", 2}};
    iiou.mean = {{"mean_iiou", "iIoU %", 2}};
    layout_.tables = {iiou};
    layout_.classes = instance_class_;
    for (size_t c = 0; c < scored_.size() && c < kind_.size(); ++c)
      kind_[c] = static_cast<uint8_t>((scored_[c] ? kScored : 0) | (instance_class_[c] ? kInstance : 0));
    instances_.assign(scored_.size(), 0);
    instance_px_.assign(scored_.size(), 0);
  }
  std::string name() const override { return layout_.key; }
  MetricInputs inputs() const override { return kGtSemantic | kGtInstanceIds | kPredSemantic; }
  uint64_t frames() const override { return frames_; }
  std::vector<std::string> conditions() const override { return keysOf(by_condition_); }
  const MetricLayout& layout() const override { return layout_; }

  uint64_t add(const EvalFrame& f) override {
    const size_t n = f.pixels(), k = scored_.size();
    if (n > 0 && (f.gt_semantic == nullptr || f.gt_instance_ids == nullptr || f.pred_semantic == nullptr))
      throw std::invalid_argument("semantic_iiou: null image");
    State& s = by_condition_[f.condition];
    s.classes.resize(k);
    struct Instance {
      uint64_t size = 0, tp = 0;
    };
    std::unordered_map<uint64_t, Instance> frame;  // by (instance id, class)
    // An instance's pixels come in runs along a row: the last one found is looked up first.
    uint64_t last_key = 0;
    Instance* last = nullptr;
    uint64_t scored = 0;
    for (size_t i = 0; i < n; ++i) {
      const uint8_t g = f.gt_semantic[i], p = f.pred_semantic[i];
      if (!(kind_[g] & kScored)) continue;
      ++scored;
      if (p != g && (kind_[p] & kInstance)) ++s.classes[p].fp;
      if (f.gt_instance_ids[i] == 0 || !(kind_[g] & kInstance)) continue;
      const uint64_t key = (static_cast<uint64_t>(static_cast<uint32_t>(f.gt_instance_ids[i])) << 8) | g;
      if (last == nullptr || key != last_key) last = &frame[key], last_key = key;
      ++last->size;
      last->tp += p == g;
    }
    for (const auto& [key, inst] : frame) {
      const uint8_t c = static_cast<uint8_t>(key & 0xff);
      s.classes[c].tp_rel += static_cast<double>(inst.tp) / static_cast<double>(inst.size);
      s.classes[c].fn_rel += static_cast<double>(inst.size - inst.tp) / static_cast<double>(inst.size);
      ++instances_[c];
      instance_px_[c] += inst.size;
    }
    ++s.frames;
    ++frames_;
    return scored;
  }

  void summarize(EvaluationSummary& s) const override {
    State all;
    all.classes.resize(scored_.size());
    for (ConditionSummary& out : s.conditions) {
      const auto it = by_condition_.find(out.condition);
      if (it == by_condition_.end()) continue;
      out.scores[name()] = scores(it->second);
      all.frames += it->second.frames;
      for (size_t c = 0; c < all.classes.size(); ++c) all.classes[c].merge(it->second.classes[c]);
    }
    if (all.frames > 0) s.all.scores[name()] = scores(all);
  }

 private:
  struct State {
    std::vector<ClassCounts> classes;
    uint64_t frames = 0;
  };

  MetricScores scores(const State& state) const {
    MetricScores out;
    out.frames = state.frames;
    std::vector<double>& per_class = out.per_class["iiou_percent"];
    per_class.assign(scored_.size(), std::numeric_limits<double>::quiet_NaN());
    double sum = 0.0;
    int count = 0;
    for (size_t c = 0; c < scored_.size(); ++c) {
      if (!instance_class_[c]) continue;
      const double avg = instances_[c] > 0 ? static_cast<double>(instance_px_[c]) / instances_[c] : 0.0;
      const ClassCounts& n = state.classes[c];
      const double tp = avg * n.tp_rel, denom = tp + static_cast<double>(n.fp) + avg * n.fn_rel;
      if (!(denom > 0.0)) continue;
      per_class[c] = 100.0 * tp / denom;
      sum += per_class[c], ++count;
    }
    out.values["mean_iiou"] = count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
    return out;
  }

  static constexpr uint8_t kScored = 1, kInstance = 2;
  std::vector<bool> scored_, instance_class_;
  std::array<uint8_t, 256> kind_{};  // per class id (any byte): kScored | kInstance
  MetricLayout layout_;
  std::map<std::string, State> by_condition_;
  std::vector<uint64_t> instances_, instance_px_;  // per class, over every condition: the average sizes
  uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeSemanticIiouMetric(const MetricContext& c) {
  return std::make_unique<SemanticIiouMetric>(c);
}

}  // namespace viper
