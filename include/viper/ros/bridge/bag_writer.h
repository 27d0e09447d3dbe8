// Writes messages into a bag as a recorder of their publishers would: one connection per topic with
// the publisher's connection header (latched where the publisher latches), header.seq numbered per
// topic as a publisher numbers its messages, each message at its header stamp. Used by
// capture_to_bag (raw bags) and generate (ground-truth bags).
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>

#include <boost/make_shared.hpp>

#include <cerrno>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

namespace viper {

class BagWriter {
 public:
  /// Opens (truncates) `path`; `compression` is none, lz4 or bz2; `callerid` names the publisher
  /// in the connection headers. Throws rosbag::BagException if the file cannot be opened.
  BagWriter(const std::string& path, const std::string& compression, const std::string& callerid)
      : bag_(std::make_unique<rosbag::Bag>()), path_(path), callerid_(callerid) {
    bag_->open(path, rosbag::bagmode::Write);
    if (compression == "lz4") bag_->setCompression(rosbag::compression::LZ4);
    else if (compression == "bz2") bag_->setCompression(rosbag::compression::BZ2);
  }
  /// Closes the bag if close() was not called. A bag that cannot be closed (a full disk) is left
  /// as it is: rosbag would throw again from its destructor, which ends the process.
  ~BagWriter() {
    try {
      if (bag_) bag_->close();
    } catch (const std::exception&) {
      (void)bag_.release();
    }
  }
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// Writes `msg` (a message with a header) on `topic` at its header stamp; sets its header.seq.
  template <typename M>
  void write(const std::string& topic, const boost::shared_ptr<M>& msg, bool latched = false) {
    msg->header.seq = seq_[topic]++;
    writeAt(topic, msg->header.stamp, msg, latched);
  }
  /// Writes `msg` (any message) on `topic` at `time`, as it is.
  template <typename M>
  void writeAt(const std::string& topic, const ros::Time& time, const boost::shared_ptr<M>& msg, bool latched = false) {
    auto& header = headers_[topic];
    if (!header) {
      header = boost::make_shared<ros::M_string>();
      (*header)["callerid"] = callerid_;
      (*header)["latching"] = latched ? "1" : "0";
      (*header)["md5sum"] = ros::message_traits::md5sum(*msg);
      (*header)["message_definition"] = ros::message_traits::definition(*msg);
      (*header)["topic"] = topic;
      (*header)["type"] = ros::message_traits::datatype(*msg);
    }
    try {
      bag_->write(topic, time, msg, header);
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(failure(e));
    }
    ++messages_;
    bytes_ += ros::serialization::serializationLength(*msg);
  }

  /// Throws std::runtime_error naming the bag if what is left cannot be written.
  void close() {
    try {
      bag_->close();
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(failure(e));
    }
  }
  uint64_t messages() const { return messages_; }
  uint64_t bytes() const { return bytes_; }

 private:
  // rosbag says "Problem writing data to disk"; the system's reason is still in errno.
  std::string failure(const rosbag::BagException& e) const {
    return path_ + ": cannot write bag: " + e.what() + " (" + std::strerror(errno) + ")";
  }
  std::unique_ptr<rosbag::Bag> bag_;
  std::string path_;
  std::string callerid_;
  std::map<std::string, boost::shared_ptr<ros::M_string>> headers_;
  std::map<std::string, uint32_t> seq_;
  uint64_t messages_ = 0;
  uint64_t bytes_ = 0;
};

}  // namespace viper
