// viper_exporter node: writes live ground-truth topics into VIPER's release layout (docs/viper_layout.md).
#include "viper/ros/dataset/live_exporter.h"
#include "viper/ros/node_shell.h"

int main(int argc, char** argv) { return viper::runNode<viper::LiveExporter>(argc, argv, "viper_exporter"); }
