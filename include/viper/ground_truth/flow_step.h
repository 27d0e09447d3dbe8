// The flow node's per-frame work on core types: frames held in a window, flow f -> f+1 and back,
// wide-baseline flow and correspondences between held frames. The flow node (through its messages,
// src/ros/ground_truth/flow_step.cpp) and the lockstep `generate` (GroundTruthPipeline) both run it
// (docs/flow_node.md).
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/ground_truth_input.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/step_problems.h"

#include <Eigen/Geometry>

#include <atomic>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viper {

/// Settings of the flow step (the flow node's parameters).
struct FlowSettings {
  FlowOptions options;    ///< occlusion thresholds
  int wide_baseline = 0;  ///< k of flow f -> f+k (0 = off)
  size_t window_size = 5; ///< frames held (>= 2 and >= wide_baseline + 1)
};

/// The flows of a frame f: forward (f-1 -> f), backward (f -> f-1), wide (f-k -> f).
enum class FlowKind { kForward, kBackward, kWide };

/// Where one flow goes: 2*width*height floats (u, v) and width*height mask bytes of the frame it
/// starts from; the flow writes every one of them.
struct FlowBuffers {
  float* uv = nullptr;
  uint8_t* visible = nullptr;
};

/// The caller's storage for flows (a pool of messages, say).
class FlowSink {
 public:
  virtual ~FlowSink() = default;
  /// Storage for flow `kind` starting from frame `from` (its size). Called on the thread that calls
  /// FlowStep::process, before the flow is computed.
  virtual FlowBuffers take(FlowKind kind, const GroundTruthInput& from) = 0;
  /// Storage for the scene flow f-1 -> f (scene_flow.h: kSceneFlowChannels floats per pixel of
  /// `from`, the frame it starts from), asked for after the forward flow's storage when
  /// FlowStep::Want::scene_flow is set; null (the default): no scene flow.
  virtual float* takeSceneFlow(const GroundTruthInput& from) {
    (void)from;
    return nullptr;
  }
};

class FlowStep {
 public:
  explicit FlowStep(const FlowSettings& settings);

  /// Which flows to compute.
  struct Want {
    bool forward = true, backward = true, wide = true;
    /// The scene flow f-1 -> f beside the forward flow (which it needs: computed then too).
    bool scene_flow = false;
  };
  /// Which flows were computed into the sink's buffers, and the stamps of the frames they start
  /// from (the backward flow's is the frame's own).
  struct Output {
    bool forward = false, backward = false, wide = false;
    bool scene_flow = false;  ///< into takeSceneFlow's buffer, from forward_from
    FrameStamp forward_from, wide_from;
  };
  /// Whether a frame of `stamp` comes after the newest held one; if not, says so in `problems`
  /// (the frame is then dropped; the window stays as it was).
  bool inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const;
  /// Forgets the held frames: a frame was dropped for its inputs, and no flow may span it.
  void startOver() { window_.clear(); }
  /// Takes one frame into the window (held until it leaves it: its pixels must not change) and
  /// computes what `want` asks for into `sink`'s buffers. `camera` is the frame's (as
  /// chooseFrameCamera gives it), `objects` the instances step's (each draw's track id associates
  /// it across frames; visible placed draws in no object get no flow), `meshes` every mesh so far.
  /// Returns false if the frame was dropped (the window then starts over: no flow spans it):
  /// a stamp not after the last, inputs that do not fit (draw indices, deformed positions, draw
  /// ids past the draws), or a null pixel pointer (whoever decoded the images said what was wrong
  /// with them). `problems` gets what was wrong, dropped or partial.
  bool process(const GroundTruthInputPtr& frame, const std::optional<FrameCamera>& camera,
               const std::vector<TrackedObject>& objects, const MeshRegistry& meshes, const Want& want,
               FlowSink& sink, Output& out, StepProblems& problems);
  /// CPU time, nanoseconds, that the last process() spent on a thread other than the caller's (the
  /// backward flow, computed beside the forward one), for the caller's CPU count.
  int64_t helperCpuNs() const { return helper_cpu_ns_; }

  /// The held frame of `stamp`, or null.
  const GroundTruthInput* held(const FrameStamp& stamp) const;
  /// The held frames' stamps in seconds, oldest first ("1.000000, 1.100000").
  std::string heldStamps() const;
  /// Flow between two held frames (the ~correspondences service) into `buffers` (a's size).
  /// Throws std::invalid_argument if either is not held, or what computeFlow throws.
  void flowBetween(const FrameStamp& a, const FrameStamp& b, const MeshRegistry& meshes, FlowBuffers buffers,
                   StepProblems& problems);
  /// The pose of held frame b's optical frame in held frame a's, when both have a usable camera.
  std::optional<Eigen::Isometry3d> relativePose(const FrameStamp& a, const FrameStamp& b) const;

  const FlowSettings& settings() const { return settings_; }

 private:
  /// One frame kept for later flow computations: the input itself (its pixels where they are).
  struct HeldFrame {
    GroundTruthInputPtr input;
    FlowFramePixels pixels;                     ///< the input's ids and metres
    std::optional<GlMatrix> camera_projection;  ///< for draws without a projection of their own
    /// Whether a flow from this frame has reported its pixels without depth (once a frame; flows
    /// from it may run on two threads).
    mutable std::atomic<bool> depth_reported{false};
    std::vector<int32_t> object_ids;  ///< per draw: track id of its object, 0 for none / stuff
    std::vector<bool> excluded;       ///< per draw: visible, placed (kHasWorld), but in no object
    std::optional<Eigen::Isometry3d> optical_from_world;  ///< nullopt: no usable camera
    std::optional<GlMatrix> camera_view;                  ///< its view matrix, where it is usable
    const CaptureFrame& frame() const { return input->frame; }
  };
  using HeldPtr = std::shared_ptr<const HeldFrame>;

  HeldPtr makeHeldFrame(const GroundTruthInputPtr& frame, const std::optional<FrameCamera>& camera,
                        const std::vector<TrackedObject>& objects, StepProblems& problems);
  HeldPtr find(const FrameStamp& stamp) const;
  /// Flow a -> b into a's width*height (u, v) pairs and mask values; and, where `scene_xyzd` is
  /// not null, the scene flow a -> b into it. Returns false if the scene flow was asked for but
  /// could not be computed (no camera in a frame: NaN everywhere, said in `problems`).
  bool flowBetween(const HeldFrame& a, const HeldFrame& b, const MeshRegistry& meshes, FlowBuffers buffers,
                   StepProblems& problems, float* scene_xyzd = nullptr);
  /// Forward (prev to cur) and backward flow side by side, on this thread and another; the scene
  /// flow after the forward one where `want_scene` (`scene_done`: computed).
  void bothWays(const HeldFrame& prev, const HeldFrame& cur, const MeshRegistry& meshes, FlowSink& sink,
                StepProblems& problems, bool want_scene, bool& scene_done);

  FlowSettings settings_;
  std::deque<HeldPtr> window_;  // oldest first; consecutive capture frames
  uint64_t frames_lost_ = 0;    // frames missing between consecutive frames seen, in all
  int64_t helper_cpu_ns_ = 0;   // the last process()'s CPU on the helper thread
};

}  // namespace viper
