#include "viper/ros/ground_truth/ground_truth_pipeline.h"

namespace viper {

GroundTruthPipeline::GroundTruthPipeline(LabelTable labels, ClassTable classes, const GroundTruthSettings& settings)
    : settings_(settings),
      instances_(std::move(labels), classes, settings.instances),
      boxes_(classes, settings.odometry.map_frame),
      odometry_([&] {
        OdometrySettings o = settings.odometry;
        o.make_path = false;  // the bag and the layout keep the poses; a path per frame is O(n^2)
        return o;
      }()),
      flow_(settings.flow) {}

bool GroundTruthPipeline::process(const FrameMessages& raw, GroundTruthMessages& out, StepProblems& problems,
                                  StageTimes* times) {
  out = GroundTruthMessages();
  if (raw.mesh_store) {
    instances_.addMeshes(*raw.mesh_store, problems);
    boxes_.addMeshes(*raw.mesh_store, problems);
    if (settings_.flow_enabled) flow_.addMeshes(*raw.mesh_store, problems);
  }
  OdometryStep::Output odometry;
  {
    StageTimer t(times, "odometry");
    if (odometry_.process(*raw.draws, odometry, problems)) out.odometry = odometry;
  }
  {
    StageTimer t(times, "instances");
    if (!instances_.process(*raw.draws, *raw.draw_ids, InstancesStep::Want(), out.instances, problems)) return false;
  }
  {
    StageTimer t(times, "boxes");
    boxes_.process(*out.instances.objects, *raw.draws, out.boxes, problems);
  }
  if (settings_.flow_enabled) {
    StageTimer t(times, "flow");
    FlowStep::Want want;
    want.wide = settings_.flow.wide_baseline > 0;
    flow_.process(*raw.draws, raw.depth, raw.draw_ids, raw.primitive_ids, *out.instances.objects, want, out.flow,
                  problems);
  }
  return true;
}

}  // namespace viper
