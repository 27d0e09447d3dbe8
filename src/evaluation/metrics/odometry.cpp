// Metric "odometry": KITTI visual-odometry errors over segments of the ground-truth path.
#include "viper/evaluation/evaluation.h"

#include <stdexcept>

namespace viper {
namespace {

class OdometryMetric : public Metric {
 public:
  explicit OdometryMetric(const MetricContext& c)
      : lengths_m_(c.options.odometry_lengths_m), step_frames_(c.options.odometry_step_frames) {}
  std::string name() const override { return "odometry"; }
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
  void fill(const std::vector<const Trajectory*>& trajectories, ConditionSummary& out) const {
    std::vector<SegmentError> errors;
    for (const Trajectory* t : trajectories) {
      out.odometry_poses += t->gt.size();
      for (size_t i = 1; i < t->gt.size(); ++i)
        out.odometry_path_m += (t->gt[i].translation() - t->gt[i - 1].translation()).norm();
      const auto e = kittiSegmentErrors(t->gt, t->est, lengths_m_, step_frames_);
      errors.insert(errors.end(), e.begin(), e.end());
    }
    out.odometry_sequences = trajectories.size();
    out.odometry = summarizeSegments(errors, lengths_m_);
  }

  std::vector<double> lengths_m_;
  size_t step_frames_;
  std::map<std::string, std::vector<Trajectory>> trajectories_;
  std::string last_condition_;
  uint64_t poses_ = 0;
};

}  // namespace

std::unique_ptr<Metric> makeOdometryMetric(const MetricContext& c) { return std::make_unique<OdometryMetric>(c); }

}  // namespace viper
