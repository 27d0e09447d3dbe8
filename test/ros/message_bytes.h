// The bytes of ROS messages, for the tests that compare messages byte for byte: a message's
// serialisation, and the bytes a message read back holds (a rosbag::MessageInstance, a
// topic_tools::ShapeShifter).
#pragma once

#include <ros/serialization.h>

#include <cstdint>
#include <vector>

namespace viper {
namespace test {

/// The serialisation of message `m`.
template <typename M>
std::vector<uint8_t> serialized(const M& m) {
  std::vector<uint8_t> out(ros::serialization::serializationLength(m));
  ros::serialization::OStream stream(out.data(), static_cast<uint32_t>(out.size()));
  ros::serialization::serialize(stream, m);
  return out;
}

/// The bytes `held` holds: anything with size() and write(stream), as rosbag::MessageInstance and
/// topic_tools::ShapeShifter.
template <typename H>
std::vector<uint8_t> heldBytes(const H& held) {
  std::vector<uint8_t> out(held.size());
  ros::serialization::OStream stream(out.data(), static_cast<uint32_t>(out.size()));
  held.write(stream);
  return out;
}

}  // namespace test
}  // namespace viper
