// Parameters every node reads the same way.
#pragma once

#include <ros/ros.h>

namespace viper {

/// `~queue_size` of `private_nh` (default `fallback`): the node's subscriber, synchroniser and
/// publisher queues. A value below 1 is named in a ROS error and `fallback` used instead.
inline int queueSizeParam(const ros::NodeHandle& private_nh, int fallback = 10) {
  int queue_size = fallback;
  private_nh.param("queue_size", queue_size, fallback);
  if (queue_size < 1) {
    ROS_ERROR("%s: ~queue_size must be >= 1 (got %d); using %d", private_nh.getNamespace().c_str(), queue_size,
              fallback);
    queue_size = fallback;
  }
  return queue_size;
}

}  // namespace viper
