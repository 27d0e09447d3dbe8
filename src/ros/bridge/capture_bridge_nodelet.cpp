// capture_bridge as a nodelet: the same CaptureBridge, sharing images zero-copy inside a manager.
#include "viper/ros/bridge/capture_bridge.h"
#include "viper/ros/node_shell.h"

VIPER_SHELL_NODELET(CaptureBridgeNodelet, CaptureBridge)
