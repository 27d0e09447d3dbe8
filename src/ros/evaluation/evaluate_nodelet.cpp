// The evaluate node as a nodelet, so it scores the ground-truth nodelets' images zero-copy in the
#include "viper/ros/evaluation/evaluate.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(EvaluateNodelet, Evaluate)
