// One shell for every node class: the same class runs as a node (its own process, runNode) and as
// a nodelet (ShellNodelet), so a whole pipeline can run zero-copy in one nodelet manager.
// A node class T is built from (node handle, private node handle) and started with start() or
// start(bool is_node) (false when it is a nodelet); stop(), where it has one, is called at the end.
// A nodelet library defines and exports each of its nodelets with VIPER_SHELL_NODELET.
#pragma once

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include <memory>

namespace viper {
namespace node_shell {

template <typename T>
auto start(T& node, bool is_node, int) -> decltype(node.start(is_node)) {
  return node.start(is_node);
}
template <typename T>
bool start(T& node, bool, long) {
  return node.start();
}
template <typename T>
auto stop(T& node, int) -> decltype(node.stop(), void()) {
  node.stop();
}
template <typename T>
void stop(T&, long) {}
template <typename T>
auto exitCode(const T& node, int) -> decltype(node.exitCode()) {
  return node.exitCode();
}
template <typename T>
int exitCode(const T&, long) {
  return 0;
}

}  // namespace node_shell

/// The body of a node's main: init, start (exit code 1 if the configuration is impossible), spin;
/// then stop, and the node's exitCode() where it has one.
template <typename T>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  T node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node_shell::start(node, /*is_node=*/true, 0)) {
    ros::shutdown();
    return 1;
  }
  ros::spin();
  node_shell::stop(node, 0);
  return node_shell::exitCode(node, 0);
}

/// Nodelet shell around a node class T.
template <typename T>
class ShellNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    node_ = std::make_unique<T>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!node_shell::start(*node_, /*is_node=*/false, 0))
      NODELET_FATAL("nodelet '%s' not started (see the message above)", getName().c_str());
  }
  std::unique_ptr<T> node_;
};

}  // namespace viper

/// Defines viper::NAME, the ShellNodelet around the node class viper::T, and exports it to pluginlib
/// (nodelet_plugins.xml names it as type viper::NAME). Used at file scope, outside any namespace.
#define VIPER_SHELL_NODELET(NAME, T)      \
  namespace viper {                       \
  class NAME : public ShellNodelet<T> {}; \
  }                                       \
  PLUGINLIB_EXPORT_CLASS(viper::NAME, nodelet::Nodelet)
