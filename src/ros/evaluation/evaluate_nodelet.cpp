// The evaluate node as a nodelet, so it scores the ground-truth nodelets' images zero-copy in the
#include "viper/ros/evaluation/evaluate.h"
#include "viper/ros/node_shell.h"

#include <pluginlib/class_list_macros.hpp>

namespace viper {
class EvaluateNodelet : public ShellNodelet<Evaluate> {};
}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::EvaluateNodelet, nodelet::Nodelet)
