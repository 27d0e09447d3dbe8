// What the tests of the package's bag readers (test_bag_reader.cpp, test_bag_reader_damage.cpp)
// share: a message read back (topic, time, connection header, bytes) from rosbag::View,
// dataset::BagFileReader (with a bulk sink or without) and viper::BagReader; bags written by
// rosbag's C++ writer and by BagFileWriter with several topics and chunks that overlap in time, and
// with large images.
#pragma once

#include "viper/dataset/bag_file_reader.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/bridge/bag_writer.h"

#include "message_bytes.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace {

struct Read {
  std::string topic;
  uint32_t sec, nsec;
  std::map<std::string, std::string> fields;
  std::vector<uint8_t> bytes;
  bool operator==(const Read& o) const {
    return std::tie(topic, sec, nsec, fields, bytes) == std::tie(o.topic, o.sec, o.nsec, o.fields, o.bytes);
  }
  bool operator<(const Read& o) const {
    return std::tie(sec, nsec, topic, fields, bytes) < std::tie(o.sec, o.nsec, o.topic, o.fields, o.bytes);
  }
};

// rosbag's messages; `error`: what it threw where it could not read on (nullptr: fail the test).
// A message as rosbag's View gives it.
inline Read readOf(const rosbag::MessageInstance& m) {
  return {m.getTopic(), m.getTime().sec, m.getTime().nsec, *m.getConnectionHeader(), viper::test::heldBytes(m)};
}

// A message as BagFileReader gives it (its bytes in the reader's buffer).
inline Read readOf(const viper::dataset::BagMessage& m) {
  return {m.connection->topic, m.sec, m.nsec, m.connection->fields, {m.data, m.data + m.size}};
}

// A message as viper::BagReader gives it.
inline Read readOf(const viper::BagReadMessage& m) {
  return {m.topic(), m.time().sec, m.time().nsec, m.connection().fields, {m.data(), m.data() + m.size()}};
}

inline std::vector<Read> readWithRosbag(const std::string& path, std::string* error = nullptr) {
  std::vector<Read> out;
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) out.push_back(readOf(m));
  } catch (const std::exception& e) {
    if (error == nullptr) ADD_FAILURE() << "rosbag: " << e.what();
    else *error = e.what();
  }
  return out;
}

// A sink that takes the bulk of every message offered, from `offset` = `split` of the bytes it is
// shown (1: all of them, the block boundary where BagFileWriter puts one), into storage of its own.
struct TestSink : viper::dataset::BagBulkSink {
  explicit TestSink(double split) : split(split) {}
  uint8_t* bulk(const viper::dataset::BagConnection&, const uint8_t*, uint32_t available, uint32_t size,
                uint32_t& offset) override {
    offered.push_back({available, size});
    offset = static_cast<uint32_t>(available * split);
    storage.emplace_back(std::max<size_t>(size - offset, 1));
    return storage.back().data();
  }
  double split;
  std::vector<std::pair<uint32_t, uint32_t>> offered;  // available, size
  std::deque<std::vector<uint8_t>> storage;
  size_t given = 0;  // messages that came with their bulk in the storage
};

inline std::vector<Read> readWithReader(const std::string& path, std::string* error = nullptr,
                                        TestSink* sink = nullptr) {
  std::vector<Read> out;
  try {
    viper::dataset::BagFileReader bag(path);
    bag.setBulkSink(sink);
    viper::dataset::BagMessage m;
    while (bag.next(m)) {
      out.push_back(readOf(m));
      if (m.bulk) {
        std::vector<uint8_t>& bytes = out.back().bytes;
        std::copy(m.bulk, m.bulk + (m.size - m.bulk_offset), bytes.begin() + m.bulk_offset);
        ++sink->given;
      }
    }
  } catch (const std::runtime_error& e) {
    if (error == nullptr) ADD_FAILURE() << e.what();
    else *error = e.what();
  }
  return out;
}

inline std::string text(size_t n, std::mt19937& random) {
  std::string s(n, ' ');
  for (char& c : s) c = static_cast<char>('a' + random() % 26);
  return s;
}

// A connection header as rosbag record stores one (rosbag's writer stores a given header as it is).
template <typename M>
boost::shared_ptr<ros::M_string> header(const std::string& callerid, bool latched) {
  return boost::make_shared<ros::M_string>(ros::M_string{{"type", ros::message_traits::datatype<M>()},
                                                         {"md5sum", ros::message_traits::md5sum<M>()},
                                                         {"message_definition", ros::message_traits::definition<M>()},
                                                         {"callerid", callerid},
                                                         {"latching", latched ? "1" : "0"}});
}

// `bag` opened for writing at `path` by rosbag's writer, compressed with `compression`, in 4 KB chunks.
inline void openWith4KbChunks(rosbag::Bag& bag, const std::string& path, rosbag::compression::CompressionType compression) {
  bag.open(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(4096);
}

// 40 frames of four topics by rosbag's writer in 4 KB chunks: an image and a text at each frame's
// time (equal times), a second connection of the image topic (another callerid), a latched text, and
// a topic written 0.35 s behind the others, so that chunks overlap in time.
inline void writeWithRosbag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag;
  openWith4KbChunks(bag, path, compression);
  std::mt19937 random(3);
  for (uint32_t f = 0; f < 40; ++f) {
    const ros::Time time(10 + f / 10, 100000000u * (f % 10));
    sensor_msgs::Image image;
    image.header.stamp = time;
    image.width = 32, image.height = 16, image.encoding = "rgb8", image.step = 96;
    image.data.resize(image.step * image.height);
    for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = static_cast<uint8_t>(f % 3 ? (i / 64) : random());
    bag.write("/camera/image", time, image, header<sensor_msgs::Image>("/player", false));
    std_msgs::String info;
    info.data = "frame " + std::to_string(f) + text(100, random);
    bag.write("/camera/info", time, info);
    if (f % 5 == 0) bag.write("/camera/image", time, image, header<sensor_msgs::Image>("/second", false));
    if (f % 7 == 0) bag.write("/latched", time, info, header<std_msgs::String>("/player", true));
    if (f >= 4) bag.write("/late", time - ros::Duration(0.35), info);
  }
  bag.close();
}

// A connection header of type M as BagFileWriter's callers give one.
template <typename M>
std::map<std::string, std::string> writerFields() {
  return {{"type", ros::message_traits::datatype<M>()},
          {"md5sum", ros::message_traits::md5sum<M>()},
          {"message_definition", ros::message_traits::definition<M>()},
          {"callerid", "/writer"},
          {"latching", "0"}};
}

// Serialises `message` into the bag (its bulk, an image's pixels, from `bulk_offset` on; 0: none).
template <typename M>
void put(viper::dataset::BagFileWriter& bag, uint32_t connection, const ros::Time& t, const M& message,
         uint32_t bulk_offset = 0) {
  const uint32_t size = ros::serialization::serializationLength(message);
  ros::serialization::OStream s(bag.beginMessage(connection, t.sec, t.nsec, size, bulk_offset), size);
  ros::serialization::serialize(s, message);
}

inline sensor_msgs::Image shapedImage(const ros::Time& t, uint32_t width, uint32_t height, const char* encoding, uint32_t bpp) {
  sensor_msgs::Image image;
  image.header.stamp = t;
  image.width = width, image.height = height, image.encoding = encoding, image.step = width * bpp;
  image.data.resize(image.step * image.height);
  return image;
}

inline void writeFile(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Six 1.5 MB images and a text at each time: by rosbag's writer (its LZ4 blocks of 1 MB fall
// anywhere in a message) or by BagFileWriter, with the pixels' offset (`bulk`: a block starts there)
// or without (its blocks of 4 MB start at the chunk's start).
enum class Writer { kRosbag, kViperBulk, kViper };

inline void writeLargeImages(const std::string& path, Writer writer) {
  std::optional<rosbag::Bag> rosbag_bag;
  std::optional<viper::dataset::BagFileWriter> viper_bag;
  uint32_t image_conn = 0, text_conn = 0;
  if (writer == Writer::kRosbag) {
    rosbag_bag.emplace(path, rosbag::bagmode::Write);
    rosbag_bag->setCompression(rosbag::compression::LZ4);
  } else {
    viper_bag.emplace(path);
    image_conn = viper_bag->addConnection("/image", writerFields<sensor_msgs::Image>());
    text_conn = viper_bag->addConnection("/text", writerFields<std_msgs::String>());
  }
  std::mt19937 random(9);
  for (uint32_t f = 0; f < 6; ++f) {
    const ros::Time t = ros::Time(30, 0) + ros::Duration(0.1 * f);
    sensor_msgs::Image image = shapedImage(t, 1024, 512, "rgb8", 3);
    for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = static_cast<uint8_t>(i % 97 == 0 ? random() : i / 4096 + f);
    std_msgs::String text_msg;
    text_msg.data = text(300, random);
    if (rosbag_bag) {
      rosbag_bag->write("/image", t, image);
      rosbag_bag->write("/text", t, text_msg);
      continue;
    }
    const uint32_t size = ros::serialization::serializationLength(image);
    put(*viper_bag, image_conn, t, image, writer == Writer::kViperBulk ? size - static_cast<uint32_t>(image.data.size()) : 0);
    put(*viper_bag, text_conn, t, text_msg);
  }
  if (rosbag_bag) rosbag_bag->close();
  else viper_bag->close();
}

using Topics = std::optional<std::set<std::string>>;

inline std::vector<Read> readWithBagReader(const std::string& path, const Topics& topics) {
  std::vector<Read> out;
  const auto reader = topics ? std::make_unique<viper::BagReader>(path, *topics) : std::make_unique<viper::BagReader>(path);
  viper::BagReadMessage m;
  while (reader->next(m)) {
    out.push_back(readOf(m));
    EXPECT_EQ(m.datatype(), m.connection().field("type"));
    EXPECT_EQ(m.md5sum(), m.connection().field("md5sum"));
    EXPECT_EQ(m.messageDefinition(), m.connection().field("message_definition"));
  }
  return out;
}

}  // namespace
