#include "viper/ros/ground_truth/step_log.h"

namespace viper {

const char* defaultTopicOf(StepInput input) {
  switch (input) {
    case StepInput::kDraws: return "/capture/draws";
    case StepInput::kDrawIds: return "/capture/draw_ids";
    case StepInput::kDepth: return "/capture/depth/image_raw";
    case StepInput::kPrimitiveIds: return "/capture/primitive_ids";
    case StepInput::kObjects: return "/ground_truth/objects";
    case StepInput::kMeshStore: return "/capture/mesh_store";
    case StepInput::kColor: return "/capture/color/image_raw";
  }
  return "?";
}

void StepLog::log(const StepProblems& problems) {
  for (const StepProblem& p : problems) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const ros::WallTime now = ros::WallTime::now();
      auto [it, fresh] = last_.try_emplace({p.input, p.kind}, now);
      if (!fresh) {
        if ((now - it->second).toSec() < 5.0) continue;
        it->second = now;
      }
    }
    const std::string topic = topic_of_(p.input);
    switch (p.severity) {
      case StepSeverity::kInfo: ROS_INFO("%s%s", topic.c_str(), p.text.c_str()); break;
      case StepSeverity::kWarning: ROS_WARN("%s%s", topic.c_str(), p.text.c_str()); break;
      case StepSeverity::kError: ROS_ERROR("%s%s", topic.c_str(), p.text.c_str()); break;
    }
  }
}

}  // namespace viper
