#include "viper/ros/ground_truth/boxes_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"

#include <boost/make_shared.hpp>

namespace viper {

BoxesStep::BoxesStep(ClassTable classes, std::string map_frame)
    : classes_(std::move(classes)), map_frame_(std::move(map_frame)) {}

void BoxesStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

void BoxesStep::process(const ObjectArray& objects, const DrawList& draws, Output& out, StepProblems& problems) {
  CaptureFrame& frame = frame_;  // kept: its draws' storage is reused
  fromDrawListMsg(draws, frame);
  const double t = draws.header.stamp.toSec();
  const unsigned long number = draws.frame_number;

  std::optional<Eigen::Isometry3d> optical_from_map;
  if (auto camera = chooseFrameCamera(frame)) {
    if (camera->view.allFinite()) optical_from_map = opticalFromWorld(camera->view);
  }
  if (!optical_from_map)
    problems.push_back({StepInput::kObjects, StepSeverity::kWarning, "view",
                        ": frame " + std::to_string(number) + " has no usable view matrix; boxes_optical not published"});

  out.in_map = boost::make_shared<Box3DArray>();
  out.in_map->header = draws.header;
  out.in_map->header.frame_id = map_frame_;
  Box3DArray in_optical;
  in_optical.header = draws.header;
  std::map<int32_t, LastSeen> seen;
  for (const Object& o : objects.objects) {
    if (o.track_id <= 0 || o.draws.empty()) continue;
    if (o.draws.front() >= frame.draws.size()) {
      problems.push_back({StepInput::kObjects, StepSeverity::kError, "draw_index",
                          ": track " + std::to_string(o.track_id) + " names draw " + std::to_string(o.draws.front()) +
                              " but the frame has " + std::to_string(frame.draws.size()) + " draws; object skipped"});
      continue;
    }
    FrameObject fo;
    fo.draws = o.draws;
    fo.class_id = o.class_id;
    fo.is_thing = true;
    fo.world = frame.draws[o.draws.front()].world;
    BoxStatus status;
    const OrientedBox box = objectBox(frame, fo, meshes_, &status);
    if (status != BoxStatus::kOk) {
      problems.push_back({StepInput::kObjects, StepSeverity::kWarning, "no_box",
                          ": track " + std::to_string(o.track_id) + " (" + o.class_name + "): " +
                              (status == BoxStatus::kMissingMesh      ? "none of its meshes has arrived"
                               : status == BoxStatus::kSingularMatrix ? "its world matrix is singular or not finite"
                                                                      : "it has no vertices") +
                              "; no box"});
      continue;
    }
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    auto it = last_seen_.find(o.track_id);
    if (it != last_seen_.end() && t > it->second.time_s) velocity = (box.center - it->second.center) / (t - it->second.time_s);
    seen[o.track_id] = {box.center, t};
    out.in_map->boxes.push_back(toBox3DMsg(box, o.track_id, o.class_id, classes_, velocity));
    if (optical_from_map)
      in_optical.boxes.push_back(toBox3DMsg(box.transformed(*optical_from_map), o.track_id, o.class_id, classes_,
                                            optical_from_map->linear() * velocity));
  }
  last_seen_.swap(seen);
  out.in_optical = optical_from_map ? boost::make_shared<Box3DArray>(std::move(in_optical)) : nullptr;
}

}  // namespace viper
