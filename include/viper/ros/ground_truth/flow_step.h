// The flow node's per-frame work on messages: its draw list and images decoded into a frame (its
// pixels read in the messages, which the window then holds), the core FlowStep
// (include/viper/ground_truth/flow_step.h) run on it, the flows computed into recycled messages
// (FlowMessagePools, which `generate` uses too), and the correspondences service (docs/flow_node.md).
#pragma once

#include "viper/ground_truth/flow_step.h"
#include "viper/ros/conversions/ground_truth_conversions.h"
#include "viper/ros/conversions/image_msg_pool.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <sensor_msgs/Image.h>
#include <viper/Correspondences.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

namespace viper {

class FlowMessageStep {
 public:
  explicit FlowMessageStep(const FlowSettings& settings) : step_(settings) {}

  /// Meshes of a mesh store message (deformed draws need their rest mesh).
  void addMeshes(const MeshStore& store, StepProblems& problems);

  using Want = FlowStep::Want;
  /// A frame's flows; a field is null where it was not computed. forward: frame f-1 -> f, with
  /// f-1's header; backward: f -> f-1, with f's header; wide: f-k -> f, with f-k's header;
  /// scene_flow: f-1 -> f (32FC4: dx, dy, dz, d_depth in metres, f-1's optical frame, NaN where the
  /// forward flow is; scene_flow.h), with f-1's header, where `want.scene_flow`.
  struct Output {
    FlowMessages forward, backward, wide;
    sensor_msgs::ImagePtr scene_flow;
  };
  /// Takes one synchronised frame into the window and computes what `want` asks for. Returns false
  /// if the frame was dropped (the window then starts over: no flow spans it). `problems` gets what
  /// was wrong, dropped or partial. The window holds the image messages themselves (they must not
  /// change afterwards, as no published message does), and the flows are computed into their messages.
  bool process(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
               const sensor_msgs::ImageConstPtr& draw_ids, const sensor_msgs::ImageConstPtr& primitive_ids,
               const ObjectArray& objects, const Want& want, Output& out, StepProblems& problems);
  /// CPU time, nanoseconds, that the last process() spent on a thread other than the caller's.
  int64_t helperCpuNs() const { return step_.helperCpuNs(); }

  /// Flow, mask and relative pose between two held frames (the ~correspondences service);
  /// `res.success` false with `res.message` saying why when a stamp is not held.
  void correspondences(const ros::Time& stamp_a, const ros::Time& stamp_b, Correspondences::Response& res,
                       StepProblems& problems);

  const FlowSettings& settings() const { return step_.settings(); }

 private:
  /// The flow messages, and the scene flow's (recycled 32FC4 messages).
  class Pools : public FlowMessagePools {
   public:
    float* takeSceneFlow(const GroundTruthInput& from) override;
    sensor_msgs::ImagePtr scene_flow;  ///< the last frame's, null if none was taken since clearScene()
    void clearScene() { scene_flow.reset(); }

   private:
    ImageMsgPool scene_pool_{64};
  };

  FlowStep step_;
  MeshRegistry meshes_;
  Pools pools_;
};

}  // namespace viper
