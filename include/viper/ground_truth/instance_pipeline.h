// Per-frame instance ground truth: objects, semantic ids, instance (track) ids, boundaries,
// boxes. The `instances` and `boxes` nodes are thin shells around this class.
#pragma once

#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instructions.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ground_truth/objects.h"
#include "viper/ground_truth/tracking.h"

#include <string>
#include <vector>

namespace viper {

/// Options of InstancePipeline.
struct InstancePipelineOptions {
  /// Per class id: thing classes (get instance ids and tracks). Default: VIPER's instance classes.
  std::vector<bool> thing_classes = defaultThingClasses();
  /// Weight each part's vote by its mesh's surface area (else one vote per part).
  bool area_weighted_vote = true;
  /// Compute each thing's oriented box (TrackedObject::box); a caller that does not use them (the
  /// instances node: the boxes node makes them) saves the work.
  bool compute_boxes = true;
  TrackerOptions tracker;

  /// VIPER's instance_eval classes: trafficlight, firehydrant, chair, trashcan, person,
  /// motorcycle, car, van, bus, truck.
  static std::vector<bool> defaultThingClasses();
};

/// One object of a frame, as published.
struct TrackedObject {
  int32_t track_id = 0;  ///< 0 for stuff
  FrameObject object;
  OrientedBox box;       ///< world (map) frame
  BoxStatus box_status = BoxStatus::kEmpty;
};

/// Everything derived for one frame.
struct InstanceFrame {
  std::vector<uint8_t> semantic;      ///< class id per pixel
  std::vector<int32_t> instance_ids;  ///< track id per pixel, 0 = none
  std::vector<uint8_t> boundaries;    ///< 255 on instance boundaries
  std::vector<TrackedObject> objects;
  /// Problems met (each a sentence naming the draw or object), for the node to log.
  std::vector<std::string> problems;
  bool tracker_reset = false;
};

/// Caller storage for images of InstanceFrame (a message's buffers, say): each non-null pointer
/// takes width*height values in place of its vector, which is left empty. `draw_ids`, if not null,
/// holds the frame's width*height draw ids in place of frame.draw_ids (which may then be empty):
/// the draw id message's pixels, read where they are.
struct InstanceImagesInto {
  int32_t* instance_ids = nullptr;
  uint8_t* boundaries = nullptr;
  const uint32_t* draw_ids = nullptr;
  uint8_t* semantic = nullptr;
  /// Also rendered where not null (rgb8, width*height*3 bytes), from the same runs of draws as the
  /// images above: colorizeClasses() of the class image with `classes` (which must then be set),
  /// and encodeViperInstances() of the class and instance images. The same bytes, without another
  /// pass over those images.
  uint8_t* semantic_color = nullptr;
  const ClassTable* classes = nullptr;
  uint8_t* instances_viper = nullptr;
};

/// Keeps the mesh store and the tracker across frames.
class InstancePipeline {
 public:
  InstancePipeline(LabelTable labels, InstancePipelineOptions options = InstancePipelineOptions());

  /// Processes one frame (adds its new meshes to the store first). Uses only the frame's draws,
  /// draw id image, size, number and time. Throws std::invalid_argument naming the frame if the
  /// draw id image does not match the size or the draw indices are not 0..n-1; nothing changes then.
  /// Objects whose world matrix is not finite are dropped and reported in `problems`.
  InstanceFrame process(const CaptureFrame& frame);
  /// The same, writing into `out`: its image buffers are reused when the frame size is unchanged.
  void process(const CaptureFrame& frame, InstanceFrame& out);
  /// The same, rendering the images `into` names into its storage.
  void process(const CaptureFrame& frame, InstanceFrame& out, const InstanceImagesInto& into);

  /// Adds meshes that arrive outside frames (e.g. a latched mesh store topic).
  void addMeshes(const std::vector<MeshRecord>& meshes) { meshes_.add(meshes); }
  const MeshRegistry& meshes() const { return meshes_; }
  void reset() { tracker_.reset(); }

 private:
  // into's semantic_color and instances_viper, from runs_.
  void renderPictures(const DrawAssignment& assignment, const std::vector<int32_t>& instance_of_draw,
                      const InstanceImagesInto& into) const;
  LabelTable labels_;
  InstancePipelineOptions options_;
  MeshRegistry meshes_;
  Tracker tracker_;
  DrawRuns runs_;  // of the current frame; kept for its storage
};

/// VIPER's instance encoding: R = class id, G = id / 256, B = id % 256 (ids above 65535 wrap).
/// Every path of `instructions` gives the same bytes (AVX2 32 pixels a step).
void encodeViperInstances(const uint8_t* class_ids, const int32_t* instance_ids, size_t n, uint8_t* rgb,
                          Instructions instructions = Instructions::kWidest);

}  // namespace viper
