#include "viper/ros/ground_truth/boxes_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"

namespace viper {

void BoxesMessageStep::addMeshes(const MeshStore& store, StepProblems& problems) {
  std::vector<std::string> bad;
  meshes_.add(fromMeshStoreMsg(store, bad, &meshes_));
  for (std::string& p : bad) problems.push_back({StepInput::kMeshStore, StepSeverity::kError, "mesh", ": " + p});
}

void BoxesMessageStep::process(const ObjectArray& objects, const DrawList& draws, BoxesMessages& out,
                               StepProblems& problems) {
  fromDrawListMsg(draws, frame_);
  step_.process(frame_, toFrameStamp(draws.header.stamp), chooseFrameCamera(frame_), fromObjectArrayMsg(objects),
                meshes_, boxes_, problems);
  out = toBoxesMsgs(boxes_, draws.header, map_frame_, step_.classes());
}

}  // namespace viper
