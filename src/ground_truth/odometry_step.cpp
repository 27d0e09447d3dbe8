#include "viper/ground_truth/odometry_step.h"
#include "viper/ground_truth/stamp_order.h"

#include <stdexcept>
#include <string>

namespace viper {

bool OdometryStep::inOrder(const FrameStamp& stamp, uint64_t number, StepProblems& problems) const {
  return stampAfterLast(last_stamp_, stamp, number, StepInput::kDraws, problems);
}

bool OdometryStep::process(const std::optional<FrameCamera>& camera, const FrameStamp& stamp, uint64_t number,
                           EgoFrame& out, StepProblems& problems) {
  out = EgoFrame();
  if (!inOrder(stamp, number, problems)) return false;
  if (!camera) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "no_camera",
                        ": frame " + std::to_string(number) +
                            " has no draw with a view and a projection matrix; frame dropped"});
    return false;
  }
  try {
    out.pose = egoPoseFromView(camera->view, stamp.seconds());
  } catch (const std::exception& e) {
    problems.push_back({StepInput::kDraws, StepSeverity::kError, "view",
                        ": frame " + std::to_string(number) + ": " + e.what() + "; frame dropped"});
    return false;
  }
  if (last_) out.twist = bodyTwist(*last_, out.pose);
  last_ = out.pose;
  last_stamp_ = stamp;
  return true;
}

}  // namespace viper
