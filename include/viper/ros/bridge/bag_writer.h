// Writes messages into a bag as a recorder of their publishers would: one connection per topic with
// the publisher's connection header (latched where the publisher latches), header.seq numbered per
// topic as a publisher numbers its messages, each message at its header stamp; an image's pixels
// start an LZ4 block (bag_player decompresses them straight into its message). Used by
// capture_to_bag (raw bags), generate (ground-truth bags) and viper_to_bag (which gives connection
// headers as rosbag::Bag::write stores them: writeWithHeader). The file is written by
// dataset::BagFileWriter (each message serialised once, straight into its chunk; chunks that do
// not compress stored as they are); rosbag reads it as its own.
#pragma once

#include "viper/dataset/bag_file_writer.h"

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/time.h>
#include <sensor_msgs/Image.h>

#include <boost/shared_ptr.hpp>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

namespace viper {

class BagWriter {
 public:
  /// Opens (truncates) `path`; `compression` is none, lz4 or bz2; `callerid` names the publisher
  /// in the connection headers. Throws std::runtime_error naming the file if it cannot be written,
  /// std::invalid_argument for another compression.
  BagWriter(const std::string& path, const std::string& compression, const std::string& callerid)
      : bag_(path, options(compression)), callerid_(callerid) {}
  /// Closes the bag if close() was not called (errors are then lost: call close()).
  ~BagWriter() = default;
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// Writes `msg` (a message with a header) on `topic` at its header stamp; sets its header.seq.
  template <typename M>
  void write(const std::string& topic, const boost::shared_ptr<M>& msg, bool latched = false) {
    msg->header.seq = seq_[topic]++;
    writeAt(topic, msg->header.stamp, msg, latched);
  }
  /// Writes `msg` (any message) on `topic` at `time`, as it is. Throws std::runtime_error naming
  /// the bag if it cannot be written.
  template <typename M>
  void writeAt(const std::string& topic, const ros::Time& time, const boost::shared_ptr<M>& msg, bool latched = false) {
    put(topic, time, *msg, [&] {
      std::map<std::string, std::string> fields = typeFields(*msg);
      fields["callerid"] = callerid_;
      fields["latching"] = latched ? "1" : "0";
      fields["topic"] = topic;
      return fields;
    });
  }
  /// The same on a connection whose header is `fields` where `topic` has none yet (as
  /// rosbag::Bag::write with a connection header stores it; without one it stores typeFields()).
  template <typename M>
  void writeWithHeader(const std::string& topic, const ros::Time& time, const M& msg,
                       const std::map<std::string, std::string>& fields) {
    put(topic, time, msg, [&] { return fields; });
  }
  /// A connection header of type, md5sum and message_definition.
  template <typename M>
  static std::map<std::string, std::string> typeFields(const M& msg) {
    return {{"md5sum", ros::message_traits::md5sum(msg)},
            {"message_definition", ros::message_traits::definition(msg)},
            {"type", ros::message_traits::datatype(msg)}};
  }

  /// Throws std::runtime_error naming the bag if what is left cannot be written.
  void close() { bag_.close(); }
  uint64_t messages() const { return messages_; }
  uint64_t bytes() const { return bytes_; }

 private:
  template <typename M, typename Fields>
  void put(const std::string& topic, const ros::Time& time, const M& msg, const Fields& fields) {
    auto known = connections_.find(topic);
    if (known == connections_.end()) known = connections_.emplace(topic, bag_.addConnection(topic, fields())).first;
    const uint32_t size = ros::serialization::serializationLength(msg);
    uint8_t* out = bag_.beginMessage(known->second, time.sec, time.nsec, size, bulkOffset(msg, size));
    ros::serialization::OStream stream(out, size);
    ros::serialization::serialize(stream, msg);
    ++messages_;
    bytes_ += size;
  }
  // Where a message's bulk starts (its last bytes, an image's pixels), for the bag's LZ4 blocks.
  template <typename M>
  static uint32_t bulkOffset(const M&, uint32_t) {
    return 0;
  }
  static uint32_t bulkOffset(const sensor_msgs::Image& image, uint32_t size) {
    return size - static_cast<uint32_t>(image.data.size());
  }
  static dataset::BagFileOptions options(const std::string& compression) {
    dataset::BagFileOptions o;
    o.compression = dataset::bagCompressionFromName(compression);
    return o;
  }
  dataset::BagFileWriter bag_;
  std::string callerid_;
  std::map<std::string, uint32_t> connections_;
  std::map<std::string, uint32_t> seq_;
  uint64_t messages_ = 0;
  uint64_t bytes_ = 0;
};

}  // namespace viper
