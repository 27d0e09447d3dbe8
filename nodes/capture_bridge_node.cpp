// capture_bridge node: publishes a capture stream as raw topics (see docs/capture_bridge.md).
#include "viper/ros/bridge/capture_bridge.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::CaptureBridge>(argc, argv, "capture_bridge"); }
