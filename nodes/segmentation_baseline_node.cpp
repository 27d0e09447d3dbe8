// segmentation_baseline node (see docs/baselines.md).
#include "viper/ros/baselines/segmentation_baseline.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) {
  return viper::runNode<viper::SegmentationBaseline>(argc, argv, "segmentation_baseline");
}
