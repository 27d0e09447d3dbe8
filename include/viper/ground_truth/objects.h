// Objects from draws: draws placed with the same world matrix form one object, and the object's
// class is the majority vote of its parts' resource labels (docs/ground_truth.md,
// "Objects"). Also the per-pixel images that follow from it.
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/label_table.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace viper {

/// One object of a frame.
struct FrameObject {
  /// Indices of the draws (parts) that form the object, ascending.
  std::vector<uint32_t> draws;
  /// Majority class of the parts' labels, each part voting with its weight (unlabelled parts do
  /// not vote; ties go to the class with more visible pixels, then the lower id).
  uint8_t class_id = 0;
  /// Whether class_id is a "thing" class (has instances); only things override their parts'
  /// labels in the semantic image, get instance ids and are tracked.
  bool is_thing = false;
  /// The shared world matrix (object -> world, as passed to OpenGL).
  GlMatrix world = GlMatrix::Identity();
  /// Resources of all parts (sorted, unique): used by tracking to tell objects apart.
  std::vector<uint64_t> mesh_keys, texture_keys;
  /// Visible pixels and their 2D box in pixels (inclusive; meaningful only if pixel_count > 0).
  uint32_t pixel_count = 0;
  int x_min = 0, y_min = 0, x_max = -1, y_max = -1;
};

/// Weight of a part's vote: 1 per part by default (a plain majority); e.g. the surface area of the
/// part's mesh, so that a bus body outvotes six wheels shared with cars.
using VoteWeight = std::function<double(const DrawRecord&)>;

/// Groups the frame's draws into objects. Draws without a world matrix (no kHasWorld) are left out.
/// `thing_classes[c]` says whether class c is a thing class (e.g. ClassTable::instanceEvalMask()).
/// Objects come out in the order of their first draw.
std::vector<FrameObject> groupObjects(const CaptureFrame& frame, const LabelTable& labels,
                                      const std::vector<bool>& thing_classes, const VoteWeight& weight = nullptr);

/// Per draw index: the class the semantic image shows (the object's vote for things, the draw's
/// own label otherwise) and the index of its object in `objects` (-1 for none).
struct DrawAssignment {
  std::vector<uint8_t> draw_class;
  std::vector<int32_t> draw_object;
};
DrawAssignment assignDraws(const CaptureFrame& frame, const LabelTable& labels,
                           const std::vector<FrameObject>& objects);

/// The draw id image as runs of equal ids along its rows (a run never crosses a row end), covering
/// every pixel in order: the per-pixel kernels below touch each run once instead of each pixel.
/// In the world at 1920x1080 a run is ~100 px long.
struct DrawRuns {
  struct Run {
    uint32_t start;   ///< pixel index of the first pixel (y * width + x)
    uint32_t length;  ///< pixels
    uint32_t id;      ///< draw id image value (draw index + 1; 0 = none)
    uint32_t y;       ///< row
  };
  uint32_t width = 0, height = 0;
  std::vector<Run> runs;
};

/// Splits `frame.draw_ids` into runs (reusing the storage of `runs`). The image must have
/// width * height pixels.
void findDrawRuns(const CaptureFrame& frame, DrawRuns& runs);
/// The same on the frame's width * height draw ids at `draw_ids`.
void findDrawRuns(const CaptureFrame& frame, const uint32_t* draw_ids, DrawRuns& runs);

/// Fills `pixel_count` and the 2D box of every object.
void measureObjects(const DrawRuns& runs, const DrawAssignment& assignment, std::vector<FrameObject>& objects);

/// Semantic class id image (one byte per pixel; 0 where no draw).
void renderSemantic(const DrawRuns& runs, const DrawAssignment& assignment, uint8_t* class_ids);

/// An rgb8 image of one color per draw id, filled run by run: `colors[id]` for draw ids below
/// colors.size(), `other` for the ids past them. What a per-pixel picture of the class or instance
/// images gives where each is constant over a draw (semantic_color, instances_viper), without
/// reading those images again.
void renderRgbOfDraws(const DrawRuns& runs, const std::vector<std::array<uint8_t, 3>>& colors,
                      std::array<uint8_t, 3> other, uint8_t* rgb);

/// The instance id of each draw id: `object_ids[k]` (0 = none, e.g. stuff) for the draws of
/// objects[k], 0 for the others.
std::vector<int32_t> instanceOfDraws(const DrawAssignment& assignment, const std::vector<int32_t>& object_ids);

/// Instance id image from instanceOfDraws() (draw ids past the table are 0).
void renderInstances(const DrawRuns& runs, const std::vector<int32_t>& instance_of_draw, int32_t* instance_ids);

/// Instance boundaries: 255 where a pixel's 4-neighbour (within the image) has another instance id,
/// else 0; from the runs of draws and instanceOfDraws(), without the instance id image: each row's
/// runs of one instance against those of its neighbours.
void renderBoundariesOfRuns(const DrawRuns& runs, const std::vector<int32_t>& instance_of_draw, uint8_t* boundaries);

}  // namespace viper
