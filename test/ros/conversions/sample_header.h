// The header the conversion tests stamp their messages with.
#pragma once

#include <std_msgs/Header.h>

namespace viper::test {

inline std_msgs::Header sampleHeader() {
  std_msgs::Header h;
  h.stamp = ros::Time(12, 500);
  h.frame_id = "camera_optical";
  return h;
}

}  // namespace viper::test
