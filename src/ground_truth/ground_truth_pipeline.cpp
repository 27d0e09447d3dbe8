#include "viper/ground_truth/ground_truth_pipeline.h"

namespace viper {

GroundTruthPipeline::GroundTruthPipeline(LabelTable labels, ClassTable classes, const GroundTruthSettings& settings)
    : settings_(settings),
      instances_(std::move(labels), classes, settings.instances),
      boxes_(classes),
      flow_(settings.flow) {}

bool GroundTruthPipeline::process(const GroundTruthInputPtr& input, const InstanceImagesInto& into, FlowSink& flow_sink,
                                  GroundTruthResult& out, StepProblems& problems, StageTimes* times) {
  const CaptureFrame& frame = input->frame;
  out.camera.reset();
  out.ego.reset();
  out.instances.objects.clear();  // its images' storage stays, for the next frame
  out.instances.problems.clear();
  out.boxes = FrameBoxes();
  out.flow = FlowStep::Output();
  {
    StageTimer t(times, "odometry");
    out.camera = chooseFrameCamera(frame);
    EgoFrame ego;
    if (odometry_.process(out.camera, input->stamp, frame.number, ego, problems)) out.ego = ego;
  }
  {
    StageTimer t(times, "instances");
    if (!input->draw_ids) return false;  // whoever decoded the frame said what was wrong with its ids
    if (!instances_.process(frame, input->stamp, input->draw_ids, into, out.instances, problems)) return false;
  }
  {
    StageTimer t(times, "boxes");
    boxes_.process(frame, input->stamp, out.camera, out.instances.objects, instances_.meshes(), out.boxes, problems);
  }
  if (settings_.flow_enabled) {
    StageTimer t(times, "flow");
    FlowStep::Want want;
    want.wide = settings_.flow.wide_baseline > 0;
    flow_.process(input, out.camera, out.instances.objects, instances_.meshes(), want, flow_sink, out.flow, problems);
  }
  return true;
}

}  // namespace viper
