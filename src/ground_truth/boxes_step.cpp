#include "viper/ground_truth/boxes_step.h"

#include <string>

namespace viper {

BoxesStep::BoxesStep(ClassTable classes) : classes_(std::move(classes)) {}

void BoxesStep::process(const CaptureFrame& frame, const FrameStamp& stamp, const std::optional<FrameCamera>& camera,
                        const std::vector<TrackedObject>& objects, const MeshRegistry& meshes, FrameBoxes& out,
                        StepProblems& problems) {
  out.boxes.clear();
  const double t = stamp.seconds();
  std::optional<Eigen::Isometry3d> optical_from_map;
  if (camera && camera->view.allFinite()) optical_from_map = opticalFromWorld(camera->view);
  if (!optical_from_map)
    problems.push_back({StepInput::kObjects, StepSeverity::kWarning, "view",
                        ": frame " + std::to_string(frame.number) +
                            " has no usable view matrix; boxes_optical not published"});
  out.has_optical = optical_from_map.has_value();

  std::map<int32_t, LastSeen> seen;
  for (const TrackedObject& o : objects) {
    const std::vector<uint32_t>& draws = o.object.draws;
    if (o.track_id <= 0 || draws.empty()) continue;
    if (draws.front() >= frame.draws.size()) {
      problems.push_back({StepInput::kObjects, StepSeverity::kError, "draw_index",
                          ": track " + std::to_string(o.track_id) + " names draw " + std::to_string(draws.front()) +
                              " but the frame has " + std::to_string(frame.draws.size()) + " draws; object skipped"});
      continue;
    }
    // The object as the instances step's message carries it: its draws and class; placed with the
    // world matrix of its first draw.
    FrameObject fo;
    fo.draws = draws;
    fo.class_id = o.object.class_id;
    fo.is_thing = true;
    fo.world = frame.draws[draws.front()].world;
    BoxStatus status;
    const OrientedBox box = objectBox(frame, fo, meshes, &status);
    if (status != BoxStatus::kOk) {
      const int class_id = o.object.class_id;
      const std::string name = static_cast<size_t>(class_id) < classes_.size() ? classes_.at(class_id).name
                                                                               : "class_" + std::to_string(class_id);
      problems.push_back({StepInput::kObjects, StepSeverity::kWarning, "no_box",
                          ": track " + std::to_string(o.track_id) + " (" + name + "): " +
                              (status == BoxStatus::kMissingMesh      ? "none of its meshes has arrived"
                               : status == BoxStatus::kSingularMatrix ? "its world matrix is singular or not finite"
                                                                      : "it has no vertices") +
                              "; no box"});
      continue;
    }
    TrackBox b;
    b.track_id = o.track_id;
    b.class_id = o.object.class_id;
    b.in_map = box;
    auto it = last_seen_.find(o.track_id);
    if (it != last_seen_.end() && t > it->second.time_s)
      b.velocity_map = (box.center - it->second.center) / (t - it->second.time_s);
    seen[o.track_id] = {box.center, t};
    if (optical_from_map) {
      b.in_optical = box.transformed(*optical_from_map);
      b.velocity_optical = optical_from_map->linear() * b.velocity_map;
    }
    out.boxes.push_back(b);
  }
  last_seen_.swap(seen);
}

}  // namespace viper
