// Every ground-truth step in lockstep, on core types: one decoded frame in, all its ground truth out,
// in the order and with the code the nodes of replay.launch use (odometry; instances; then boxes and
// flow on its objects). The frame's camera is derived once and its meshes are kept once, for every
// step. The `generate` command runs it (src/ros/dataset/sequence_generator.cpp) and turns its results
// into messages only where it writes a bag; a frame is never dropped for being slow.
#pragma once

#include "viper/ground_truth/amodal.h"
#include "viper/ground_truth/boxes_step.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/flow_step.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/instances_step.h"
#include "viper/ground_truth/labelled_cloud.h"
#include "viper/ground_truth/normals.h"
#include "viper/ground_truth/odometry_step.h"
#include "viper/ground_truth/stage_times.h"

#include <optional>

namespace viper {

/// Settings of every step (the nodes' parameters).
struct GroundTruthSettings {
  InstancesSettings instances;
  FlowSettings flow;
  bool flow_enabled = true;  ///< replay.launch flow:=
  bool normals = false;      ///< the normals node's `normals` (NormalsStep)
  int cloud_decimation = 0;  ///< the labelled cloud of every k-th pixel (labelledCloud); 0 = none
  bool amodal = false;       ///< amodal masks and visibility (AmodalStep)
  AmodalOptions amodal_options;
  bool scene_flow = false;   ///< the flow node's `flow/scene_flow` (with flow_enabled)
};

/// The caller's storage for the per-pixel modalities beyond instances and flow (a message's pixels,
/// say); taken on the thread that calls GroundTruthPipeline::process, each before it is computed.
class ModalitySink {
 public:
  virtual ~ModalitySink() = default;
  /// 3 * width * height floats for the frame's normals (a 32FC3 image's data).
  virtual float* takeNormals(const GroundTruthInput& frame) = 0;
  /// `size.points()` points for the frame's labelled cloud.
  virtual CloudPoint* takeCloud(const GroundTruthInput& frame, const CloudSize& size) = 0;
};

/// The ground truth of one frame.
struct GroundTruthResult {
  std::optional<FrameCamera> camera;  ///< chooseFrameCamera of the frame's draws
  std::optional<EgoFrame> ego;        ///< none where the odometry step dropped the frame
  /// The instances step's objects (none where it dropped the frame), and its images where
  /// GroundTruthPipeline::process was not given storage for them.
  InstanceFrame instances;
  FrameBoxes boxes;
  FlowStep::Output flow;  ///< which flows the sink's buffers hold (and whether the scene flow)
  bool normals = false;   ///< the normals are in the modality sink's buffer
  bool cloud = false;     ///< the labelled cloud is in the modality sink's buffer
  FrameAmodal amodal;     ///< the objects' amodal masks (settings.amodal; none where it was off)
};

class GroundTruthPipeline {
 public:
  GroundTruthPipeline(LabelTable labels, ClassTable classes, const GroundTruthSettings& settings);

  /// Meshes of the mesh store (a capture's new meshes), for every step.
  void addMeshes(const std::vector<MeshRecord>& meshes) { instances_.addMeshes(meshes); }
  const MeshRegistry& meshes() const { return instances_.meshes(); }

  /// One frame: the camera of its draws, then every step. The instance images go where `into` says
  /// (InstanceImagesInto: a message's pixels, say; into `out.instances`' vectors where it says
  /// nothing), the flows into `flow_sink`'s buffers (unless flow is off). Returns false if the
  /// instances step dropped the frame (boxes and flow are then not computed; `out.ego` may be
  /// set). With `times`, each step's CPU and wall time is added to it (stages "odometry" (with the
  /// camera), "instances", "boxes", "flow"). The modalities the settings ask for go into
  /// `modalities`' buffers (normals, cloud: stages "normals", "cloud"), into `out.amodal` ("amodal")
  /// and the scene flow into `flow_sink`'s (FlowSink::takeSceneFlow); without a modality sink no
  /// normals or cloud are computed. Normals need the frame's depth and primitive ids, the cloud its
  /// depth (and colour): a frame without them has none, and says so in `problems`.
  bool process(const GroundTruthInputPtr& frame, const InstanceImagesInto& into, FlowSink& flow_sink,
               GroundTruthResult& out, StepProblems& problems, StageTimes* times = nullptr,
               ModalitySink* modalities = nullptr);

  const ClassTable& classes() const { return instances_.classes(); }
  const GroundTruthSettings& settings() const { return settings_; }

 private:
  /// The labelled cloud of the frame into the sink's buffer (out.cloud), or a problem.
  void cloud(const GroundTruthInput& input, const uint8_t* semantic, const int32_t* instance_ids, ModalitySink& sink,
             GroundTruthResult& out, StepProblems& problems);

  GroundTruthSettings settings_;
  InstancesStep instances_;
  BoxesStep boxes_;
  OdometryStep odometry_;
  FlowStep flow_;
  NormalsStep normals_;
  AmodalStep amodal_;
};

}  // namespace viper
