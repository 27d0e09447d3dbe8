// The flow node's per-frame work without ROS plumbing: frames held in a window, flow f -> f+1 and
// back, wide-baseline flow and correspondences between held frames. The flow node and the lockstep
// `generate` both run it (docs/flow_node.md).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/flow.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/image_msg_pool.h"
#include "viper/ros/ground_truth/step_problems.h"

#include <sensor_msgs/Image.h>
#include <viper/Correspondences.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <Eigen/Geometry>

#include <atomic>
#include <deque>
#include <memory>
#include <optional>

namespace viper {

/// Settings of the flow step (the flow node's parameters).
struct FlowSettings {
  FlowOptions options;    ///< occlusion thresholds
  int wide_baseline = 0;  ///< k of flow f -> f+k (0 = off)
  size_t window_size = 5; ///< frames held (>= 2 and >= wide_baseline + 1)
};

class FlowStep {
 public:
  explicit FlowStep(const FlowSettings& settings);

  /// Meshes of a mesh store message (deformed draws need their rest mesh).
  void addMeshes(const MeshStore& store, StepProblems& problems);

  /// Which flows to compute.
  struct Want {
    bool forward = true, backward = true, wide = true;
  };
  /// A frame's flows; a field is null where it was not computed. forward: frame f-1 -> f, with
  /// f-1's header; backward: f -> f-1, with f's header; wide: f-k -> f, with f-k's header.
  struct Output {
    FlowMessages forward, backward, wide;
  };
  /// Takes one synchronised frame into the window and computes what `want` asks for. Returns false
  /// if the frame was dropped (the window then starts over: no flow spans it). `problems` gets what
  /// was wrong, dropped or partial. The window holds the image messages themselves (they must not
  /// change afterwards, as no published message does), and the flows are computed into their messages.
  bool process(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
               const sensor_msgs::ImageConstPtr& draw_ids, const sensor_msgs::ImageConstPtr& primitive_ids,
               const ObjectArray& objects, const Want& want, Output& out, StepProblems& problems);
  /// CPU time, nanoseconds, that the last process() spent on a thread other than the caller's (the
  /// backward flow, computed beside the forward one), for the caller's CPU count.
  int64_t helperCpuNs() const { return helper_cpu_ns_; }

  /// Flow, mask and relative pose between two held frames (the ~correspondences service);
  /// `res.success` false with `res.message` saying why when a stamp is not held.
  void correspondences(const ros::Time& stamp_a, const ros::Time& stamp_b, Correspondences::Response& res,
                       StepProblems& problems);

  const FlowSettings& settings() const { return settings_; }

 private:
  /// One frame kept for later flow computations: its messages, not copies of their pixels.
  struct HeldFrame {
    std_msgs::Header header;
    CaptureFrame frame;  ///< size, number and draws; no images
    sensor_msgs::ImageConstPtr depth, draw_ids, primitive_ids;
    FlowFramePixels pixels;           ///< ids and metres from the messages
    const float* depth_m = nullptr;   ///< the depth message's metres
    std::optional<GlMatrix> camera_projection;  ///< for draws without a projection of their own
    /// Whether a flow from this frame has reported its pixels without depth (once a frame; flows
    /// from it may run on two threads).
    mutable std::atomic<bool> depth_reported{false};
    std::vector<int32_t> object_ids;  ///< per draw: track id of its object, 0 for none / stuff
    std::vector<bool> excluded;       ///< per draw: visible, placed (kHasWorld), but in no object
    std::optional<Eigen::Isometry3d> optical_from_world;  ///< nullopt: no usable camera
  };
  using HeldPtr = std::shared_ptr<const HeldFrame>;

  HeldPtr makeHeldFrame(const DrawList& draws, const sensor_msgs::ImageConstPtr& depth,
                        const sensor_msgs::ImageConstPtr& draw_ids, const sensor_msgs::ImageConstPtr& primitive_ids,
                        const ObjectArray& objects, StepProblems& problems);
  /// Flow a -> b into a's width*height (u, v) pairs and mask values.
  void flowBetween(const HeldFrame& a, const HeldFrame& b, float* uv, uint8_t* visible, StepProblems& problems);
  /// Messages of the pools for the flow from a, with a's header.
  FlowMessages takeMessages(const HeldFrame& a);
  /// The same into `m`'s flow and mask.
  void flowBetween(const HeldFrame& a, const HeldFrame& b, FlowMessages& m, StepProblems& problems);
  /// The same into messages of the pools, with a's header.
  FlowMessages flowBetween(const HeldFrame& a, const HeldFrame& b, StepProblems& problems);
  /// Forward (prev to cur) and backward flow side by side, on this thread and another.
  void bothWays(const HeldFrame& prev, const HeldFrame& cur, Output& out, StepProblems& problems);

  FlowSettings settings_;
  MeshRegistry meshes_;
  std::deque<HeldPtr> window_;  // oldest first; consecutive capture frames
  // The flows' messages, recycled. Two flows a frame (and the wide one): with 32, a bag played at
  // 8 frames in flight took fresh 16 MB flow buffers, whose pages the kernel zeroed on first touch
  // (clear_page_erms under takeMessages 0.91 % of the manager; 0.05 % with 64). A pool keeps only
  // as many as were in flight at once.
  ImageMsgPool flow_pool_{64}, visible_pool_{64};
  uint64_t frames_lost_ = 0;    // frames missing between consecutive frames seen, in all
  int64_t helper_cpu_ns_ = 0;   // the last process()'s CPU on the helper thread
};

}  // namespace viper
