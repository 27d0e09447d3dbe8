// What the rostest testers (test/ros/*_tester.cpp) share: their main, and waiting on a condition
// until a deadline.
#pragma once

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdint>
#include <functional>

namespace viper {
namespace test {

/// Waits until `done()` is true, polling every 10 ms; false once `deadline` has passed or ROS is
/// shutting down.
inline bool waitFor(const std::function<bool()>& done, const ros::WallTime& deadline) {
  while (!done()) {
    if (ros::WallTime::now() > deadline || !ros::ok()) return false;
    ros::WallDuration(0.01).sleep();
  }
  return true;
}

/// A tester's main: gtest takes its flags, ROS starts this process as node `node_name`, then every
/// test runs, with an AsyncSpinner of `spinner_threads` threads running meanwhile if that is > 0.
/// Returns what RUN_ALL_TESTS returns.
inline int runTester(int argc, char** argv, const char* node_name, uint32_t spinner_threads = 0) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  if (spinner_threads == 0) return RUN_ALL_TESTS();
  ros::AsyncSpinner spinner(spinner_threads);
  spinner.start();
  return RUN_ALL_TESTS();
}

}  // namespace test
}  // namespace viper
