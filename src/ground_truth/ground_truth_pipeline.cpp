#include "viper/ground_truth/ground_truth_pipeline.h"

namespace viper {

GroundTruthPipeline::GroundTruthPipeline(LabelTable labels, ClassTable classes, const GroundTruthSettings& settings)
    : settings_(settings),
      instances_(std::move(labels), classes, settings.instances),
      boxes_(classes),
      flow_(settings.flow),
      amodal_(settings.amodal_options) {}

bool GroundTruthPipeline::process(const GroundTruthInputPtr& input, const InstanceImagesInto& into, FlowSink& flow_sink,
                                  GroundTruthResult& out, StepProblems& problems, StageTimes* times,
                                  ModalitySink* modalities) {
  const CaptureFrame& frame = input->frame;
  out.camera.reset();
  out.ego.reset();
  out.instances.objects.clear();  // its images' storage stays, for the next frame
  out.instances.problems.clear();
  out.boxes = FrameBoxes();
  out.flow = FlowStep::Output();
  out.normals = out.cloud = false;
  out.amodal.objects.clear();
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
  // The instance images, where the instances step put them.
  const uint8_t* semantic = into.semantic ? into.semantic : out.instances.semantic.data();
  const int32_t* instance_ids = into.instance_ids ? into.instance_ids : out.instances.instance_ids.data();
  if (settings_.normals && modalities) {
    StageTimer t(times, "normals");
    out.normals = normals_.process(*input, out.camera, instances_.meshes(), modalities->takeNormals(*input), problems);
  }
  if (settings_.cloud_decimation > 0 && modalities) {
    StageTimer t(times, "cloud");
    cloud(*input, semantic, instance_ids, *modalities, out, problems);
  }
  if (settings_.amodal) {
    StageTimer t(times, "amodal");
    amodal_.process(frame, out.instances.objects, instance_ids, instances_.meshes(), out.amodal, problems);
  }
  if (settings_.flow_enabled) {
    StageTimer t(times, "flow");
    FlowStep::Want want;
    want.wide = settings_.flow.wide_baseline > 0;
    want.scene_flow = settings_.scene_flow;
    flow_.process(input, out.camera, out.instances.objects, instances_.meshes(), want, flow_sink, out.flow, problems);
  }
  return true;
}

void GroundTruthPipeline::cloud(const GroundTruthInput& input, const uint8_t* semantic, const int32_t* instance_ids,
                                ModalitySink& sink, GroundTruthResult& out, StepProblems& problems) {
  const CaptureFrame& frame = input.frame;
  const std::string at = " (frame " + std::to_string(frame.number) + "): ";
  if (!input.depth_m) return;  // whoever decoded the frame said what was wrong with its depth
  if (!out.camera) {
    problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "cloud_camera",
                        at + "no draw carries a view and a projection: no labelled cloud"});
    return;
  }
  try {
    const PinholeIntrinsics intrinsics = intrinsicsFromGlProjection(out.camera->projection, frame.width, frame.height);
    CloudImages images;
    images.width = frame.width;
    images.height = frame.height;
    images.depth_m = input.depth_m;
    images.rgb = input.color_rgb;
    images.class_ids = semantic;
    images.instance_ids = instance_ids;
    const CloudSize size = cloudSize(frame.width, frame.height, settings_.cloud_decimation);
    labelledCloud(images, intrinsics, settings_.cloud_decimation, sink.takeCloud(input, size));
    out.cloud = true;
  } catch (const std::invalid_argument& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kWarning, "cloud_camera",
                        at + "no labelled cloud: " + e.what()});
  }
}

}  // namespace viper
