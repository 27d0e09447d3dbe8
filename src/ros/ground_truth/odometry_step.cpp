#include "viper/ros/ground_truth/odometry_step.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/frame_conversions.h"

namespace viper {

bool OdometryMessageStep::process(const DrawList& draws, Output& out, StepProblems& problems) {
  out = Output();
  const FrameStamp stamp = toFrameStamp(draws.header.stamp);
  if (!step_.inOrder(stamp, draws.frame_number, problems)) return false;
  fromDrawListMsg(draws, frame_);
  EgoFrame ego;
  if (!step_.process(chooseFrameCamera(frame_), stamp, draws.frame_number, ego, problems)) return false;
  out = messages_.convert(ego, draws.header);
  return true;
}

}  // namespace viper
