// Logging what a ground-truth step reports, as the nodes do: each problem with the topic of its input,
// throttled to one line per 5 s for each input and kind.
#pragma once

#include "viper/ros/ground_truth/step_problems.h"

#include <ros/ros.h>

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace viper {

class StepLog {
 public:
  /// `topic_of` names the topic an input arrives on (the node's resolved subscriber topic).
  explicit StepLog(std::function<std::string(StepInput)> topic_of) : topic_of_(std::move(topic_of)) {}
  /// Logs `problems` (ROS_INFO / ROS_WARN / ROS_ERROR by severity), throttled per input and kind.
  void log(const StepProblems& problems);

 private:
  std::function<std::string(StepInput)> topic_of_;
  std::mutex mutex_;
  std::map<std::pair<StepInput, std::string>, ros::WallTime> last_;
};

}  // namespace viper
