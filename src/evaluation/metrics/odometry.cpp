// Metric "odometry": KITTI visual-odometry errors over segments of the ground-truth path.
#include "viper/evaluation/evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace viper {
namespace {

class OdometryMetric : public Metric {
 public:
  explicit OdometryMetric(const MetricContext& c)
      : lengths_m_(c.options.odometry_lengths_m), step_frames_(c.options.odometry_step_frames) {
    const int n = ReportColumn::kCount;
    layout_.key = "odometry";
    layout_.frames_label = "odometry poses";
    layout_.summary = {{"translation_percent", "VO translation %", 2}, {"rotation_deg_per_m", "VO rotation deg/m", 4}};
    layout_.summary_csv = {{"frames", "odometry_poses", n},
                           {"path_m", "odometry_path_m"},
                           {"segments", "odometry_segments", n},
                           {"translation_percent", "odometry_translation_percent"},
                           {"rotation_deg_per_m", "odometry_rotation_deg_per_m"}};
    layout_.yaml = {{"frames", "poses", n},
                    {"path_m", "path_m"},
                    {"segments", "segments", n},
                    {"translation_percent", "translation_percent"},
                    {"rotation_deg_per_m", "rotation_deg_per_m"}};
    layout_.markdown = {{MarkdownPart::kText, "## Visual odometry (KITTI)\n\n"},
                        {MarkdownPart::kTable, "overall"},
                        {MarkdownPart::kText, "\n### By segment length\n\n"},
                        {MarkdownPart::kTable, "by_length"},
                        {MarkdownPart::kNote, ""},
                        {MarkdownPart::kText, "\n![VO error over segment length](odometry_errors.png)\n"}};
    const ReportColumn segments{"segments", "segments", n}, translation{"translation_percent", "translation %", 2},
        rotation{"rotation_deg_per_m", "rotation deg/m", 4};
    ReportTable overall, by_length, csv;
    overall.kind = by_length.kind = csv.kind = ReportTable::kRows;
    overall.name = "overall", overall.rows = {"overall"};
    overall.columns = {{"frames", "poses", n}, {"sequences", "sequences", n}, {"path_m", "path m", 1}, segments,
                       translation, rotation};
    by_length.name = "by_length", by_length.rows = {"by_length"}, by_length.skip_zero = "segments";
    by_length.columns = {{"length_m", "length m", ReportColumn::kShortest}, segments, translation, rotation};
    csv.name = "odometry_csv", csv.file = "odometry.csv", csv.always = true, csv.rows = {"by_length", "overall"};
    csv.columns = {{"length_m", "length_m"}, segments, {"translation_percent", "translation_percent"},
                   {"rotation_deg_per_m", "rotation_deg_per_m"}};
    layout_.tables = {overall, by_length, csv};
    PlotLayout plot;
    plot.file = "odometry_errors.png";
    plot.width = 640, plot.height = 460;
    plot.when = "segments";
    PlotLayout::Panel t, r;
    t.axes.title = "VO translation error";
    r.axes.title = "VO rotation error";
    t.axes.x_label = r.axes.x_label = "segment length (m)";
    t.axes.y_label = "translation error (%)";
    r.axes.y_label = "rotation error (deg/m)";
    t.axes.x_min = r.axes.x_min = 0.0;
    t.axes.x_max = r.axes.x_max =
        lengths_m_.empty() ? 1.0 : *std::max_element(lengths_m_.begin(), lengths_m_.end()) * 1.05;
    t.axes.markers = r.axes.markers = true;
    t.axes.y_max = r.axes.y_max = 0.0;  // from the data
    t.x = r.x = lengths_m_;
    t.curves = {{"translation", ""}};
    r.curves = {{"rotation", ""}};
    plot.panels = {t, r};
    layout_.plots = {plot};
  }
  std::string name() const override { return layout_.key; }
  const MetricLayout& layout() const override { return layout_; }
  MetricInputs inputs() const override { return kGtPose | kPredPose; }
  uint64_t frames() const override { return poses_; }
  std::vector<std::string> conditions() const override { return keysOf(trajectories_); }

  // Poses of one condition with increasing frame numbers form one trajectory.
  uint64_t add(const EvalFrame& f) override {
    if (f.gt_pose == nullptr || f.pred_pose == nullptr) throw std::invalid_argument("Evaluation::addPose: null pose");
    std::vector<Trajectory>& runs = trajectories_[f.condition];
    const bool continues = !runs.empty() && last_condition_ == f.condition && f.frame_number > runs.back().last_frame;
    if (!continues) runs.emplace_back();
    Trajectory& t = runs.back();
    t.gt.push_back(*f.gt_pose);
    t.est.push_back(*f.pred_pose);
    t.last_frame = f.frame_number;
    last_condition_ = f.condition;
    ++poses_;
    return 1;
  }

  void summarize(EvaluationSummary& s) const override {
    std::vector<const Trajectory*> all;
    for (ConditionSummary& out : s.conditions) {
      std::vector<const Trajectory*> runs;
      if (const auto it = trajectories_.find(out.condition); it != trajectories_.end())
        for (const Trajectory& t : it->second) runs.push_back(&t);
      fill(runs, out);
      all.insert(all.end(), runs.begin(), runs.end());
    }
    fill(all, s.all);
  }

 private:
  struct Trajectory {
    std::vector<Eigen::Isometry3d> gt, est;
    uint64_t last_frame = 0;
  };
  // Values: path_m, sequences, segments, translation_percent, rotation_deg_per_m; row sets
  // "overall" (those and poses) and "by_length" (per segment length); curves translation and
  // rotation (by length).
  void fill(const std::vector<const Trajectory*>& trajectories, ConditionSummary& out) const {
    std::vector<SegmentError> errors;
    uint64_t poses = 0;
    double path_m = 0.0;
    for (const Trajectory* t : trajectories) {
      poses += t->gt.size();
      for (size_t i = 1; i < t->gt.size(); ++i) path_m += (t->gt[i].translation() - t->gt[i - 1].translation()).norm();
      const auto e = kittiSegmentErrors(t->gt, t->est, lengths_m_, step_frames_);
      errors.insert(errors.end(), e.begin(), e.end());
    }
    const OdometryScores o = summarizeSegments(errors, lengths_m_);
    MetricScores& s = out.scores[name()];
    s.frames = poses;
    s.values = {{"path_m", path_m},
                {"sequences", static_cast<double>(trajectories.size())},
                {"segments", static_cast<double>(o.segments)},
                {"translation_percent", o.translation_percent},
                {"rotation_deg_per_m", o.rotation_deg_per_m}};
    ReportRow overall;
    overall.text["length_m"] = "all";
    overall.values = s.values;
    overall.values["frames"] = static_cast<double>(poses);
    s.rows["overall"] = {overall};
    for (size_t i = 0; i < o.lengths_m.size(); ++i) {
      ReportRow row;
      row.values = {{"length_m", o.lengths_m[i]},
                    {"segments", static_cast<double>(o.segments_per_length[i])},
                    {"translation_percent", o.translation_percent_by_length[i]},
                    {"rotation_deg_per_m", o.rotation_deg_per_m_by_length[i]}};
      s.rows["by_length"].push_back(row);
    }
    s.curves["translation"] = o.translation_percent_by_length;
    s.curves["rotation"] = o.rotation_deg_per_m_by_length;
    if (o.segments == 0) {
      char path[64] = "-";
      if (std::isfinite(path_m)) std::snprintf(path, sizeof(path), "%.1f", path_m);
      s.note = "\nNo segment: the ground-truth path (" + std::string(path) +
               " m) is shorter than the shortest segment length.\n";
    }
  }

  std::vector<double> lengths_m_;
  size_t step_frames_;
  MetricLayout layout_;
  std::map<std::string, std::vector<Trajectory>> trajectories_;
  std::string last_condition_;
  uint64_t poses_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeOdometryMetric(const MetricContext& c) { return std::make_unique<OdometryMetric>(c); }

}  // namespace viper
