// Reads a bag's messages as rosbag::View does and hands them out typed, BagWriter's counterpart:
// the messages of the topics asked for (or of every topic), by time, each with its connection
// (topic, type, md5sum, message definition, callerid), its time in the bag and its bytes;
// instantiate<M>() deserialises one as rosbag's MessageInstance::instantiate does (null where the
// connection's md5sum is not M's). The file is read by dataset::BagFileReader (faster than
// rosbag, LZ4 checksums verified), which reads only the chunks that hold messages of the topics
// asked for, as rosbag does. A damaged chunk among them is an error once (BagReadError, with the
// messages of it skipped); the next call reads on after it, as rosbag reads on after one.
// Messages of equal time come in file order; rosbag orders those of different connections as its
// sort of per-connection iterators leaves them.
#pragma once

#include "viper/dataset/bag_file_reader.h"

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/time.h>

#include <boost/make_shared.hpp>
#include <boost/shared_ptr.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper {

/// A message of a damaged chunk, not read: its connection and time, as the bag's index has them.
struct BagSkippedMessage {
  const dataset::BagConnection* connection = nullptr;  // the reader's: valid while it lives
  ros::Time time;
  const std::string& topic() const { return connection->topic; }
};

/// A bag that cannot be opened or read on: what() names the file and what is wrong, problem()
/// says only what is wrong. From next(), for a damaged chunk: skipped() lists its messages of the
/// topics asked for (at least one), and reading can go on after them.
class BagReadError : public std::runtime_error {
 public:
  BagReadError(const std::string& path, const std::string& what, std::vector<BagSkippedMessage> skipped = {})
      : std::runtime_error(what),
        problem_(what.compare(0, path.size() + 2, path + ": ") == 0 ? what.substr(path.size() + 2) : what),
        skipped_(std::move(skipped)) {}
  const std::string& problem() const { return problem_; }
  /// The messages of a damaged chunk, skipped, in play order; empty where the bag cannot be read on.
  const std::vector<BagSkippedMessage>& skipped() const { return skipped_; }

 private:
  std::string problem_;
  std::vector<BagSkippedMessage> skipped_;
};

/// A message of a bag, valid until its reader's next call.
class BagReadMessage {
 public:
  const dataset::BagConnection& connection() const { return *message_.connection; }
  const std::string& topic() const { return message_.connection->topic; }
  const std::string& datatype() const { return message_.connection->field("type"); }
  const std::string& md5sum() const { return message_.connection->field("md5sum"); }
  const std::string& messageDefinition() const { return message_.connection->field("message_definition"); }
  /// Its time in the bag (the record's, not its header stamp).
  ros::Time time() const { return ros::Time(message_.sec, message_.nsec); }
  /// Its serialised bytes.
  const uint8_t* data() const { return message_.data; }
  uint32_t size() const { return message_.size; }

  /// The message as an M, or null if the connection's md5sum is not M's (either may be "*", any
  /// type). Throws ros::serialization's exception (a ros::Exception) if the bytes are too few.
  template <typename M>
  boost::shared_ptr<M> instantiate() const {
    const char* md5 = ros::message_traits::md5sum<M>();
    if (md5 == nullptr) return {};
    if (md5[0] != '*' && md5sum() != "*" && md5sum() != md5) return {};
    auto msg = boost::make_shared<M>();
    ros::serialization::PreDeserializeParams<M> params;
    params.message = msg;
    params.connection_header = *header_;
    ros::serialization::PreDeserialize<M>::notify(params);
    ros::serialization::IStream in(const_cast<uint8_t*>(message_.data), message_.size);
    ros::serialization::deserialize(in, *msg);
    return msg;
  }

 private:
  friend class BagReader;
  dataset::BagMessage message_;
  const boost::shared_ptr<std::map<std::string, std::string>>* header_ = nullptr;
};

class BagReader {
 public:
  /// Opens `path` and reads its index, to read every topic. Throws BagReadError naming the file
  /// and what is wrong (a bag without an index: `rosbag reindex` recovers it).
  explicit BagReader(const std::string& path) { open(path); }
  /// The same, to read only `topics` (rosbag::TopicQuery).
  BagReader(const std::string& path, const std::set<std::string>& topics) : topics_(topics) { open(path); }
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  const std::string& path() const { return bag_->path(); }
  /// The connections of the wanted topics, by id (rosbag::View(bag, TopicQuery).getConnections()).
  const std::vector<const dataset::BagConnection*>& connections() const { return connections_; }
  /// Every connection of the bag (rosbag::View(bag).getConnections()), by id.
  const std::vector<const dataset::BagConnection*>& bagConnections() const { return all_; }
  /// The messages of the wanted topics (rosbag::View's size()).
  uint64_t size() const { return size_; }

  /// The next message of the wanted topics; false after the last. Throws BagReadError naming the
  /// file and where it is damaged, after every message before the damage; for a damaged chunk, with
  /// its messages skipped(), and the next call reads on after them.
  bool next(BagReadMessage& m) {
    try {
      if (!bag_->next(m.message_)) return false;
    } catch (const dataset::BagDamagedChunk& e) {
      std::vector<BagSkippedMessage> skipped;
      for (const dataset::BagIndexedMessage& s : e.skipped()) skipped.push_back({s.connection, ros::Time(s.sec, s.nsec)});
      throw BagReadError(path(), e.what(), std::move(skipped));
    } catch (const std::runtime_error& e) {
      throw BagReadError(path(), e.what());
    }
    m.header_ = &headers_.at(m.message_.connection->id);
    return true;
  }
  /// next(), reading on after each damaged chunk: `damaged(const BagReadError&)` is called with it
  /// (its skipped() messages, in play order, where the first of them would have come), then the
  /// next message follows. Other errors are thrown as next() throws them.
  template <typename OnDamagedChunk>
  bool nextReadingOn(BagReadMessage& m, OnDamagedChunk&& damaged) {
    for (;;) {
      try {
        return next(m);
      } catch (const BagReadError& e) {
        if (e.skipped().empty()) throw;
        damaged(e);
      }
    }
  }

 private:
  void open(const std::string& path) {
    try {
      bag_ = std::make_unique<dataset::BagFileReader>(path);
    } catch (const std::runtime_error& e) {
      throw BagReadError(path, e.what());
    }
    if (topics_) bag_->select([this](const dataset::BagConnection& c) { return wanted(c.topic); });
    for (const dataset::BagConnection& c : bag_->connections()) {
      headers_.emplace(c.id, boost::make_shared<std::map<std::string, std::string>>(c.fields));
      if (c.messages == 0) continue;  // rosbag::View lists the connections with messages
      all_.push_back(&c);
      if (!wanted(c.topic)) continue;
      connections_.push_back(&c);
      size_ += c.messages;
    }
  }
  bool wanted(const std::string& topic) const { return !topics_ || topics_->count(topic) != 0; }

  std::optional<std::set<std::string>> topics_;
  std::unique_ptr<dataset::BagFileReader> bag_;
  std::map<uint32_t, boost::shared_ptr<std::map<std::string, std::string>>> headers_;
  std::vector<const dataset::BagConnection*> connections_, all_;
  uint64_t size_ = 0;
};

}  // namespace viper
