// What BagFileWriter and BagFileReader share of ROS bag format 2.0
// (http://wiki.ros.org/Bags/Format/2.0): the record opcodes (rosbag's constants.h), the version line,
// the time as the format packs it, and the fields of a record header.
#pragma once

#include <cstdint>
#include <cstring>
#include <string_view>

namespace viper::dataset::bag_format {

constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpFileHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;
/// The file header record's header and padding together (the index position is written into it last).
constexpr uint32_t kFileHeaderLength = 4096;
constexpr char kVersion[] = "#ROSBAG V2.0\n";
constexpr size_t kVersionLength = sizeof(kVersion) - 1;

/// sec in the low 32 bits, nsec in the high ones (a little-endian ros::Time).
inline uint64_t packTime(uint32_t sec, uint32_t nsec) { return static_cast<uint64_t>(nsec) << 32 | sec; }

/// A little-endian value from `bytes` (x86 and ARM are little endian, as the format is).
template <typename T>
T load(const uint8_t* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// Calls f(name, value) for each field "name=value" (each after its 4-byte length) of a record
/// header of `size` bytes; false (having called f for the fields before) where a length runs past
/// the header or a field has no '='. rosbag splits a field at its first '=' too.
template <typename F>
bool forEachField(const uint8_t* header, uint32_t size, F&& f) {
  uint32_t at = 0;
  while (at < size) {
    if (size - at < 4) return false;
    const uint32_t length = load<uint32_t>(header + at);
    at += 4;
    if (length > size - at) return false;
    const std::string_view field(reinterpret_cast<const char*>(header + at), length);
    const size_t equals = field.find('=');
    if (equals == std::string_view::npos) return false;
    f(field.substr(0, equals), field.substr(equals + 1));
    at += length;
  }
  return true;
}

}  // namespace viper::dataset::bag_format
