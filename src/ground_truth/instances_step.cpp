#include "viper/ground_truth/instances_step.h"
#include "viper/ground_truth/stamp_order.h"

#include <stdexcept>
#include <string>

namespace viper {

InstancesStep::InstancesStep(LabelTable labels, ClassTable classes, const InstancesSettings& settings)
    : classes_(std::move(classes)) {
  if (settings.extrapolate_frames < 0)
    throw std::invalid_argument("extrapolate_frames must be >= 0 (got " + std::to_string(settings.extrapolate_frames) + ")");
  InstancePipelineOptions options;
  options.thing_classes = classes_.instanceEvalMask();
  options.thing_classes.resize(256, false);
  options.area_weighted_vote = settings.area_weighted_vote;
  options.compute_boxes = false;  // the boxes step makes them
  options.tracker.extrapolate_frames = settings.extrapolate_frames;
  options.tracker.lod_tolerance_m = settings.lod_tolerance_m;
  options.tracker.resume_by_resources = settings.resume_tracks_by_resources;
  pipeline_ = std::make_unique<InstancePipeline>(std::move(labels), options);
}

bool InstancesStep::inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const {
  return stampAfterLast(last_stamp_, stamp, number, StepInput::kDrawIds, problems);
}

bool InstancesStep::process(const CaptureFrame& frame, const FrameStamp& stamp, const uint32_t* draw_ids,
                            InstanceImagesInto into, InstanceFrame& out, StepProblems& problems) {
  if (!inOrder(stamp, frame.number, problems)) return false;
  into.draw_ids = draw_ids;
  if (into.semantic_color && !into.classes) into.classes = &classes_;
  try {
    pipeline_->process(frame, out, into);
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDrawIds, StepSeverity::kError, "pipeline", std::string(": ") + e.what() + "; frame dropped"});
    return false;
  }
  last_stamp_ = stamp;
  for (const std::string& p : out.problems)
    problems.push_back({StepInput::kDrawIds, StepSeverity::kWarning, "objects", ": " + p});
  return true;
}

}  // namespace viper
