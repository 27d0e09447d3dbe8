// The baseline nodes as nodelets, to run zero-copy in replay.launch's manager.
#include "viper/ros/baselines/flow_baseline.h"
#include "viper/ros/baselines/segmentation_baseline.h"
#include "viper/ros/baselines/vo_baseline.h"

#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(FlowBaselineNodelet, FlowBaseline)
VIPER_SHELL_NODELET(VoBaselineNodelet, VoBaseline)
VIPER_SHELL_NODELET(SegmentationBaselineNodelet, SegmentationBaseline)
