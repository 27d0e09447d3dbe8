// The package's own bag reader (dataset::BagFileReader, bag_player's) against rosbag::View, on bags
// written by rosbag's C++ writer and by BagFileWriter with each compression, several topics and
// chunks that overlap in time, and on the committed test bag: every message comes back with its
// topic, time, connection header and bytes, in rosbag's order. And the errors: a bag without its
// index names `rosbag reindex`; a damaged chunk names its byte offset after every message before it
// came back, and reading goes on after it; damaged bags never crash the reader. Then
// viper::BagReader, the typed reader over it (generate's and the tools'), against rosbag::View with a
// TopicQuery and MessageInstance::instantiate; a damaged chunk of other topics is not read.
#include "viper/dataset/bag_file_reader.h"
#include "viper/ros/bridge/bag_reader.h"
#include "viper/ros/bridge/bag_writer.h"

#include "../common/process_util.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace {

using viper::dataset::BagFileReader;
using viper::test::readFile;
using viper::test::tempDir;

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
std::vector<Read> readWithRosbag(const std::string& path, std::string* error = nullptr) {
  std::vector<Read> out;
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      Read r{m.getTopic(), m.getTime().sec, m.getTime().nsec, *m.getConnectionHeader(), std::vector<uint8_t>(m.size())};
      ros::serialization::OStream s(r.bytes.data(), static_cast<uint32_t>(r.bytes.size()));
      m.write(s);
      out.push_back(std::move(r));
    }
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

std::vector<Read> readWithReader(const std::string& path, std::string* error = nullptr, TestSink* sink = nullptr) {
  std::vector<Read> out;
  try {
    BagFileReader bag(path);
    bag.setBulkSink(sink);
    viper::dataset::BagMessage m;
    while (bag.next(m)) {
      out.push_back({m.connection->topic, m.sec, m.nsec, m.connection->fields, {m.data, m.data + m.size}});
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

// BagFileReader's messages of the connections `wanted` selects (nullptr: all), reading on after
// each damaged chunk; `errors` gets each (nullptr: fail the test; their skipped messages'
// connections are gone with the reader). Another error ends the reading.
std::vector<Read> readOnWithReader(const std::string& path, std::vector<viper::dataset::BagDamagedChunk>* errors,
                                   const std::function<bool(const viper::dataset::BagConnection&)>* wanted = nullptr) {
  std::vector<Read> out;
  try {
    BagFileReader bag(path);
    if (wanted) bag.select(*wanted);
    viper::dataset::BagMessage m;
    for (size_t damaged = 0; damaged <= 1000;) {
      try {
        if (!bag.next(m)) break;
        out.push_back({m.connection->topic, m.sec, m.nsec, m.connection->fields, {m.data, m.data + m.size}});
      } catch (const viper::dataset::BagDamagedChunk& e) {
        if (errors == nullptr) ADD_FAILURE() << e.what();
        else errors->push_back(e);
        EXPECT_FALSE(e.skipped().empty()) << e.what();
        if (++damaged > 1000) ADD_FAILURE() << "read on after 1000 damaged chunks";
      }
    }
  } catch (const std::runtime_error&) {  // the index, or the file: nothing to read on after
  }
  return out;
}

// How rosbag orders messages of equal time on different connections is up to its std::sort of
// per-connection iterators; BagFileReader keeps file order. kExact where the two agree on a bag.
enum class Ties { kExact, kAsMultiset };

void expectSameReads(const std::string& path, const std::vector<Read>& got, const std::vector<Read>& expected,
                     Ties ties) {
  ASSERT_EQ(got.size(), expected.size());
  ASSERT_GT(got.size(), 0u);
  size_t differently_ordered = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(std::tie(got[i].sec, got[i].nsec), std::tie(expected[i].sec, expected[i].nsec)) << "message " << i;
    differently_ordered += !(got[i] == expected[i]);
  }
  if (ties == Ties::kExact) {
    EXPECT_EQ(differently_ordered, 0u) << "messages in another order than rosbag's";
    return;
  }
  // The same messages at each time; each connection's in the same order.
  std::vector<Read> a = got, b = expected;
  std::stable_sort(a.begin(), a.end()), std::stable_sort(b.begin(), b.end());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]) << "the messages at time " << a[i].sec << "." << a[i].nsec;
  auto ofConnection = [](const std::vector<Read>& all, const Read& c) {
    std::vector<Read> out;
    for (const Read& r : all)
      if (r.topic == c.topic && r.fields == c.fields) out.push_back(r);
    return out;
  };
  for (const Read& r : expected) EXPECT_TRUE(ofConnection(got, r) == ofConnection(expected, r)) << r.topic;
  std::cout << path << ": " << got.size() << " messages, " << differently_ordered
            << " at a place where rosbag orders equal times otherwise\n";
}

void expectSameMessages(const std::string& path, Ties ties) {
  SCOPED_TRACE(path);
  expectSameReads(path, readWithReader(path), readWithRosbag(path), ties);
}

std::string text(size_t n, std::mt19937& random) {
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

// 40 frames of four topics by rosbag's writer in 4 KB chunks: an image and a text at each frame's
// time (equal times), a second connection of the image topic (another callerid), a latched text, and
// a topic written 0.35 s behind the others, so that chunks overlap in time.
void writeWithRosbag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(4096);
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

sensor_msgs::Image shapedImage(const ros::Time& t, uint32_t width, uint32_t height, const char* encoding, uint32_t bpp) {
  sensor_msgs::Image image;
  image.header.stamp = t;
  image.width = width, image.height = height, image.encoding = encoding, image.step = width * bpp;
  image.data.resize(image.step * image.height);
  return image;
}

// The same shape by BagFileWriter in 100 KB chunks: a 147 KB noise image (its chunks stored plain
// with lz4), a flat image at the same time, and a text written 0.25 s behind.
void writeWithBagFileWriter(const std::string& path, viper::dataset::BagCompression compression) {
  viper::dataset::BagFileOptions options;
  options.compression = compression;
  options.chunk_threshold = 100 * 1024;
  viper::dataset::BagFileWriter bag(path, options);
  const auto image_fields = writerFields<sensor_msgs::Image>();
  const uint32_t noise = bag.addConnection("/noise", image_fields), flat = bag.addConnection("/flat", image_fields);
  const uint32_t late = bag.addConnection("/late", writerFields<std_msgs::String>());
  std::mt19937 random(5);
  for (uint32_t f = 0; f < 12; ++f) {
    const ros::Time t = ros::Time(20, 0) + ros::Duration(0.1 * f);
    sensor_msgs::Image image = shapedImage(t, 192, 192, "rgba8", 4);
    for (uint8_t& b : image.data) b = static_cast<uint8_t>(random());
    put(bag, noise, t, image);
    std::fill(image.data.begin(), image.data.end(), static_cast<uint8_t>(f));
    put(bag, flat, t, image);
    std_msgs::String s;
    s.data = text(500, random);
    if (f >= 3) put(bag, late, t - ros::Duration(0.25), s);
  }
  bag.close();
}

TEST(BagFileReader, ReadsRosbagsBagsAsRosbagDoes) {
  const std::string dir = tempDir("viper_bag_reader_");
  for (const auto& [name, compression] : {std::pair{"none", rosbag::compression::Uncompressed},
                                          std::pair{"lz4", rosbag::compression::LZ4},
                                          std::pair{"bz2", rosbag::compression::BZ2}}) {
    const std::string path = dir + "/rosbag_" + name + ".bag";
    writeWithRosbag(path, compression);
    expectSameMessages(path, Ties::kAsMultiset);
  }
}

TEST(BagFileReader, ReadsBagFileWritersBagsAsRosbagDoes) {
  const std::string dir = tempDir("viper_bag_reader_");
  for (const char* name : {"none", "lz4", "bz2"}) {
    const std::string path = dir + "/viper_" + name + ".bag";
    writeWithBagFileWriter(path, viper::dataset::bagCompressionFromName(name));
    expectSameMessages(path, Ties::kAsMultiset);
  }
}

void writeFile(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Six 1.5 MB images and a text at each time: by rosbag's writer (its LZ4 blocks of 1 MB fall
// anywhere in a message) or by BagFileWriter, with the pixels' offset (`bulk`: a block starts there)
// or without (its blocks of 4 MB start at the chunk's start).
enum class Writer { kRosbag, kViperBulk, kViper };

void writeLargeImages(const std::string& path, Writer writer) {
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

// With a sink, each large message's bulk comes in the sink's storage, the bytes as rosbag reads them;
// in BagFileWriter's bags with bulk offsets, the sink is first shown exactly the bytes before the
// pixels (a block ends there), so that every block of the pixels is decompressed into its storage.
TEST(BagFileReader, ASinkGetsTheBulkOfLargeMessagesAsRosbagReadsThem) {
  const std::string dir = tempDir("viper_bag_reader_");
  for (const auto& [name, writer] : {std::pair{"rosbag", Writer::kRosbag}, std::pair{"viper_bulk", Writer::kViperBulk},
                                     std::pair{"viper", Writer::kViper}}) {
    const std::string path = dir + "/large_" + name + ".bag";
    writeLargeImages(path, writer);
    const std::vector<Read> expected = readWithRosbag(path);
    ASSERT_EQ(expected.size(), 12u);
    for (double split : {1.0, 0.5}) {
      SCOPED_TRACE(std::string(name) + " split " + std::to_string(split));
      TestSink sink(split);
      const std::vector<Read> got = readWithReader(path, nullptr, &sink);
      ASSERT_EQ(got.size(), expected.size());
      std::vector<Read> a = got, b = expected;
      std::stable_sort(a.begin(), a.end()), std::stable_sort(b.begin(), b.end());
      for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]) << "message " << i << " on " << a[i].topic;
      EXPECT_EQ(sink.given, 6u) << "every image's bulk in the sink's storage";
      if (writer == Writer::kViperBulk) {
        ASSERT_EQ(sink.offered.size(), 6u);
        for (const auto& [available, size] : sink.offered)
          EXPECT_EQ(size - available, 1024u * 512 * 3) << "shown exactly the image's fields, up to its pixels";
      }
    }
  }
}

// A damaged chunk whose bulk went to the sink is named as any other, after every message before it.
TEST(BagFileReader, ADamagedChunkWithASinkIsNamedAfterTheMessagesBeforeIt) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag", damaged = dir + "/damaged.bag";
  writeLargeImages(intact, Writer::kViperBulk);
  std::string bytes = readFile(intact);
  size_t field = 0;
  for (int k = 0; k < 3; ++k) field = bytes.find("compression=lz4", field + 1);
  ASSERT_NE(field, std::string::npos);
  // BagFileWriter's chunk header: its length, then op (4 + 4 bytes), then the compression field's
  // length and text.
  const size_t chunk = field - 16;
  ASSERT_EQ(bytes.substr(chunk + 8, 4), std::string("op=\x05", 4));
  uint32_t header_size, data_size;
  std::memcpy(&header_size, bytes.data() + chunk, 4);
  std::memcpy(&data_size, bytes.data() + chunk + 4 + header_size, 4);
  const size_t data_at = chunk + 8 + header_size;
  for (size_t i = data_at + data_size - 2000; i < data_at + data_size - 1990; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  writeFile(damaged, bytes);
  TestSink sink(1.0), intact_sink(1.0);
  std::string error;
  const std::vector<Read> got = readWithReader(damaged, &error, &sink), all = readWithReader(intact, nullptr, &intact_sink);
  EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos) << error;
  ASSERT_GT(got.size(), 0u);
  ASSERT_LT(got.size(), all.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
}

TEST(BagFileReader, ReadsTheCommittedTestBagAsRosbagDoes) {
  expectSameMessages(VIPER_SOURCE_DIR "/bags/test_scene_raw.bag", Ties::kExact);
}

TEST(BagFileReader, ConnectionsAreTheIndexsWithTheirHeaders) {
  const std::string path = tempDir("viper_bag_reader_") + "/connections.bag";
  writeWithRosbag(path, rosbag::compression::LZ4);
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  const BagFileReader reader(path);
  ASSERT_EQ(reader.connections().size(), view.getConnections().size());
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    const auto mine = std::find_if(reader.connections().begin(), reader.connections().end(),
                                   [&](const viper::dataset::BagConnection& m) { return m.id == c->id; });
    ASSERT_NE(mine, reader.connections().end()) << "connection " << c->id;
    EXPECT_EQ(mine->topic, c->topic);
    EXPECT_EQ(mine->fields, *c->header);
    EXPECT_EQ(mine->field("type"), c->datatype);
    EXPECT_EQ(mine->field("md5sum"), c->md5sum);
    EXPECT_EQ(mine->field("message_definition"), c->msg_def);
    EXPECT_EQ(mine->messages, rosbag::View(bag, [&](const rosbag::ConnectionInfo* o) { return o->id == c->id; }).size());
    EXPECT_EQ(mine->field("latching") == "1", mine->topic == "/latched") << mine->topic;
    EXPECT_EQ(mine->field("no such field"), "");
  }
  EXPECT_EQ(reader.messageCount(), view.size());
}

std::string withIndexPosition(std::string bytes, uint64_t* index_position) {
  const size_t at = bytes.find("index_pos=");
  EXPECT_NE(at, std::string::npos);
  std::memcpy(index_position, bytes.data() + at + 10, 8);
  std::memset(bytes.data() + at + 10, 0, 8);
  return bytes;
}


// What a recorder that did not finish leaves: its chunks, and the file header's index position
// still 0 (rosbag writes it on close); and a bag cut short before its index.
TEST(BagFileReader, ABagWithoutIndexNamesRosbagReindex) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/whole.bag", rosbag::compression::LZ4);
  uint64_t index_position = 0;
  const std::string unfinished = withIndexPosition(readFile(dir + "/whole.bag"), &index_position);
  ASSERT_GT(index_position, 0u);
  writeFile(dir + "/unfinished.bag", unfinished.substr(0, index_position));
  writeFile(dir + "/cut.bag", readFile(dir + "/whole.bag").substr(0, index_position));
  EXPECT_THROW(rosbag::Bag(dir + "/unfinished.bag", rosbag::bagmode::Read), rosbag::BagUnindexedException);
  for (const char* name : {"/unfinished.bag", "/cut.bag"}) {
    const std::string path = dir + name;
    try {
      BagFileReader bag(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find("`rosbag reindex"), std::string::npos) << what;
      std::cout << what << "\n";
    }
  }
}

// 30 texts of 1500 bytes on one topic, times rising, in 4 KB chunks.
void writeTextBag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(4096);
  std::mt19937 random(11);
  for (uint32_t i = 0; i < 30; ++i) {
    std_msgs::String s;
    s.data = text(1500, random);
    bag.write("/text", ros::Time(5, i * 1000u), s);
  }
}

// A copy of `intact` at `damaged` with 16 bytes of its n-th chunk's data (from 1) inverted (chunks
// written by rosbag, compressed with `compression`); returns the chunk's offset (npos: no n-th chunk).
size_t damageChunk(const std::string& intact, const std::string& compression, const std::string& damaged, int n) {
  std::string bytes = readFile(intact);
  // rosbag writes a chunk's header fields by name: compression first, after the record's and the
  // field's lengths.
  size_t field = 0;
  for (int k = 0; k < n && field != std::string::npos; ++k) field = bytes.find("compression=" + compression, field + 1);
  if (field == std::string::npos) return field;
  const size_t chunk = field - 8;
  uint32_t header_size;
  std::memcpy(&header_size, bytes.data() + chunk, 4);
  for (size_t i = chunk + 8 + header_size + 40; i < chunk + 8 + header_size + 56; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  writeFile(damaged, bytes);
  return chunk;
}

size_t damageThirdChunk(const std::string& intact, const std::string& compression, const std::string& damaged) {
  return damageChunk(intact, compression, damaged, 3);
}

// Twelve texts of 5000 bytes, one a chunk (rosbag's writer, 4 KB chunks): /a at times 1, 3, .., 11
// (chunks 1, 3, ..), /b at 2, 4, .., 12.
void writeOneMessageChunks(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(4096);
  std::mt19937 random(13);
  for (uint32_t t = 1; t <= 12; ++t) {
    std_msgs::String s;
    s.data = text(5000, random);
    bag.write(t % 2 ? "/a" : "/b", ros::Time(t, 0), s);
  }
  bag.close();
}

// For each compression that can be damaged (lz4, bz2): the bag `write` writes with its n-th chunk
// damaged, checked by check(its path, the chunk's offset, the intact bag's messages by rosbag).
void withDamagedChunk(void (*write)(const std::string&, rosbag::compression::CompressionType), int n,
                      const std::function<void(const std::string&, size_t, const std::vector<Read>&)>& check) {
  const std::string dir = tempDir("viper_bag_reader_");
  for (const auto& [name, compression] : {std::pair{"lz4", rosbag::compression::LZ4},
                                          std::pair{"bz2", rosbag::compression::BZ2}}) {
    SCOPED_TRACE(name);
    const std::string intact = dir + "/intact_" + name + ".bag", damaged = dir + "/damaged_" + name + ".bag";
    write(intact, compression);
    const size_t chunk = damageChunk(intact, name, damaged, n);
    ASSERT_NE(chunk, std::string::npos);
    check(damaged, chunk, readWithRosbag(intact));
  }
}

// A chunk's data with 16 bytes inverted (the third chunk of a bag of one topic, times rising): the
// error names the chunk's offset, after the messages of the chunks before it, as many as rosbag gives.
TEST(BagFileReader, ADamagedChunkIsNamedAfterTheMessagesBeforeIt) {
  withDamagedChunk(writeTextBag, 3, [](const std::string& damaged, size_t chunk, const std::vector<Read>& all) {
    std::string error, rosbag_error;
    const std::vector<Read> got = readWithReader(damaged, &error);
    const std::vector<Read> before = readWithRosbag(damaged, &rosbag_error);
    EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos) << error;
    EXPECT_FALSE(rosbag_error.empty()) << "rosbag read the damaged chunk";
    EXPECT_GT(got.size(), 0u);
    EXPECT_EQ(got.size(), before.size()) << "as many messages as rosbag gives before the damage";
    ASSERT_LT(got.size(), all.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
    std::cout << got.size() << " of " << all.size() << " messages, then: " << error << "\n";
  });
}

// An LZ4 chunk that still decodes, to other bytes: its last literal changed (the last 5 bytes of an
// LZ4 block are literals; the frame ends with an end mark and the content checksum, 4 bytes each),
// or its stored checksum changed. Only the content checksum tells: the chunk is named as damaged.
TEST(BagFileReader, AnLz4ChunkThatDecodesToOtherBytesFailsItsChecksum) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag";
  writeTextBag(intact, rosbag::compression::LZ4);
  const std::string whole = readFile(intact);
  size_t field = 0;
  for (int k = 0; k < 3; ++k) field = whole.find("compression=lz4", field + 1);
  ASSERT_NE(field, std::string::npos);
  const size_t chunk = field - 8;
  uint32_t header_size, data_size;
  std::memcpy(&header_size, whole.data() + chunk, 4);
  std::memcpy(&data_size, whole.data() + chunk + 4 + header_size, 4);
  const size_t data_end = chunk + 8 + header_size + data_size;
  const std::vector<Read> all = readWithRosbag(intact);
  for (const auto& [what, at] : {std::pair{"last literal", data_end - 9}, std::pair{"stored checksum", data_end - 1}}) {
    SCOPED_TRACE(what);
    std::string bytes = whole;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x20);
    const std::string damaged = dir + "/damaged.bag";
    writeFile(damaged, bytes);
    std::string error;
    const std::vector<Read> got = readWithReader(damaged, &error);
    EXPECT_NE(error.find(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": LZ4: " +
                         "ERROR_contentChecksum_invalid"), std::string::npos) << error;
    ASSERT_GT(got.size(), 0u);
    ASSERT_LT(got.size(), all.size());
    for (size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i] == all[i]) << "message " << i;
    // Read on: the chunk's messages skipped, every other one as in the intact bag.
    std::vector<viper::dataset::BagDamagedChunk> errors;
    const std::vector<Read> on = readOnWithReader(damaged, &errors);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors[0].position(), chunk);
    const size_t lost = errors[0].skipped().size();
    ASSERT_EQ(on.size() + lost, all.size());
    for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == all[i < got.size() ? i : i + lost]) << "message " << i;
  }
}

// The first two chunks, read and checked side by side, both decoding to other bytes (their last
// literals changed): each is an error when it is reached, the first's not hiding the second's.
TEST(BagFileReader, TwoChunksCheckedSideBySideAreEachNamedAndReadingGoesOn) {
  const std::string dir = tempDir("viper_bag_reader_"), intact = dir + "/intact.bag", damaged = dir + "/damaged.bag";
  writeTextBag(intact, rosbag::compression::LZ4);
  std::string bytes = readFile(intact);
  std::vector<size_t> chunks;
  for (size_t field = bytes.find("compression=lz4"); chunks.size() < 2; field = bytes.find("compression=lz4", field + 1)) {
    ASSERT_NE(field, std::string::npos);
    const size_t chunk = field - 8;
    uint32_t header_size, data_size;
    std::memcpy(&header_size, bytes.data() + chunk, 4);
    std::memcpy(&data_size, bytes.data() + chunk + 4 + header_size, 4);
    const size_t last_literal = chunk + 8 + header_size + data_size - 9;
    bytes[last_literal] = static_cast<char>(bytes[last_literal] ^ 0x20);
    chunks.push_back(chunk);
  }
  writeFile(damaged, bytes);
  const std::vector<Read> all = readWithRosbag(intact);
  std::vector<viper::dataset::BagDamagedChunk> errors;
  const std::vector<Read> on = readOnWithReader(damaged, &errors);
  ASSERT_EQ(errors.size(), 2u);
  size_t lost = 0;
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(errors[k].position(), chunks[k]);
    EXPECT_NE(std::string(errors[k].what()).find("ERROR_contentChecksum_invalid"), std::string::npos) << errors[k].what();
    lost += errors[k].skipped().size();
  }
  ASSERT_EQ(on.size() + lost, all.size());
  for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == all[i + lost]) << "message " << i;
}

// The index's second entry pointing past its chunk (rosbag writes an index record's fields by name:
// conn, count, op, ver; then its data's length and the entries, sec, nsec, offset).
TEST(BagFileReader, AnIndexOffsetPastItsChunkIsNamed) {
  const std::string dir = tempDir("viper_bag_reader_"), path = dir + "/offset.bag";
  writeTextBag(dir + "/intact.bag", rosbag::compression::Uncompressed);
  std::string bytes = readFile(dir + "/intact.bag");
  const size_t op = bytes.find(std::string("op=\x04", 4)), chunk = bytes.find("compression=none") - 8;
  ASSERT_NE(op, std::string::npos);
  const uint32_t offset = 0xFFFFFF00u;
  std::memcpy(bytes.data() + op + 4 + 4 + 8 + 4 + 12 + 8, &offset, 4);
  writeFile(path, bytes);
  std::string error;
  const std::vector<Read> got = readWithReader(path, &error), all = readWithRosbag(dir + "/intact.bag");
  EXPECT_NE(error.find(path + ": damaged chunk at byte " + std::to_string(chunk) + ": the record at offset " +
                       std::to_string(offset)),
            std::string::npos)
      << error;
  ASSERT_EQ(got.size(), 1u) << "the message before";
  EXPECT_TRUE(got[0] == all[0]);
}

// Bytes flipped anywhere, or the file cut anywhere: the reader reads or throws std::runtime_error,
// and never reads outside what it holds (run under a sanitizer to see that).
TEST(BagFileReader, DamageAnywhereIsAnErrorNotACrash) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/small.bag", rosbag::compression::LZ4);
  const std::string whole = readFile(dir + "/small.bag");
  std::mt19937 random(1);
  int errors = 0;
  for (int i = 0; i < 300; ++i) {
    std::string bytes = whole;
    if (i % 3 == 0) {
      bytes.resize(random() % bytes.size());
    } else {
      const size_t at = random() % bytes.size();
      for (size_t k = at; k < std::min(bytes.size(), at + 1 + random() % 8); ++k) bytes[k] = static_cast<char>(random());
    }
    writeFile(dir + "/damaged.bag", bytes);
    std::string error;
    readWithReader(dir + "/damaged.bag", &error);
    errors += !error.empty();
    std::vector<viper::dataset::BagDamagedChunk> damaged;
    readOnWithReader(dir + "/damaged.bag", &damaged);  // and reading on after damaged chunks
  }
  EXPECT_GT(errors, 100) << "most damage is noticed";
}

TEST(BagFileReader, EmptyBagsAndOtherFiles) {
  const std::string dir = tempDir("viper_bag_reader_");
  rosbag::Bag(dir + "/rosbag_empty.bag", rosbag::bagmode::Write).close();
  viper::dataset::BagFileWriter(dir + "/viper_empty.bag").close();
  for (const char* name : {"/rosbag_empty.bag", "/viper_empty.bag"}) {
    BagFileReader bag(dir + name);
    viper::dataset::BagMessage m;
    EXPECT_TRUE(bag.connections().empty());
    EXPECT_EQ(bag.messageCount(), 0u);
    EXPECT_FALSE(bag.next(m));
  }
  writeFile(dir + "/text.bag", "not a bag\n");
  for (const std::string& path : {dir + "/text.bag", dir + "/missing.bag"}) {
    try {
      BagFileReader bag(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    }
  }
}

// viper::BagReader, the typed reader over BagFileReader (the tools' and generate's), against
// rosbag::View with a TopicQuery: the same messages of the topics asked for (time, topic,
// connection header, bytes), the same size and connections, instantiate<M>() as rosbag's; errors
// as BagReadError naming the file.

// 16 frames by viper::BagWriter: an image and a text at each frame's stamp, a latched text.
void writeWithBagWriter(const std::string& path, const std::string& compression) {
  viper::BagWriter bag(path, compression, "/writer");
  std::mt19937 random(7);
  for (uint32_t f = 0; f < 16; ++f) {
    const ros::Time t = ros::Time(30, 0) + ros::Duration(0.05 * f);
    auto image = boost::make_shared<sensor_msgs::Image>(shapedImage(t, 64, 32, "rgb8", 3));
    for (uint8_t& b : image->data) b = static_cast<uint8_t>(f % 2 ? random() : f);
    bag.write("/camera/image", image);
    auto info = boost::make_shared<std_msgs::String>();
    info->data = text(200, random);
    bag.writeAt("/camera/info", t, info);
    if (f % 4 == 0) bag.writeAt("/latched", t, info, /*latched=*/true);
  }
  bag.close();
}

using Topics = std::optional<std::set<std::string>>;

std::vector<Read> readWithBagReader(const std::string& path, const Topics& topics) {
  std::vector<Read> out;
  const auto reader = topics ? std::make_unique<viper::BagReader>(path, *topics) : std::make_unique<viper::BagReader>(path);
  viper::BagReadMessage m;
  while (reader->next(m)) {
    out.push_back({m.topic(), m.time().sec, m.time().nsec, m.connection().fields, {m.data(), m.data() + m.size()}});
    EXPECT_EQ(m.datatype(), m.connection().field("type"));
    EXPECT_EQ(m.md5sum(), m.connection().field("md5sum"));
    EXPECT_EQ(m.messageDefinition(), m.connection().field("message_definition"));
  }
  return out;
}

std::vector<uint32_t> ids(const std::vector<const rosbag::ConnectionInfo*>& connections) {
  std::vector<uint32_t> out;
  for (const auto* c : connections) out.push_back(c->id);
  return out;
}
std::vector<uint32_t> ids(const std::vector<const viper::dataset::BagConnection*>& connections) {
  std::vector<uint32_t> out;
  for (const auto* c : connections) out.push_back(c->id);
  return out;
}

void expectReadsAsRosbagView(const std::string& path, const Topics& topics) {
  SCOPED_TRACE(path + (topics ? " topics " + std::to_string(topics->size()) : " every topic"));
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::unique_ptr<rosbag::View> view = topics ? std::make_unique<rosbag::View>(
                                                    bag, rosbag::TopicQuery(std::vector<std::string>(topics->begin(), topics->end())))
                                              : std::make_unique<rosbag::View>(bag);
  std::vector<Read> expected;
  for (const rosbag::MessageInstance& m : *view) {
    Read r{m.getTopic(), m.getTime().sec, m.getTime().nsec, *m.getConnectionHeader(), std::vector<uint8_t>(m.size())};
    ros::serialization::OStream s(r.bytes.data(), static_cast<uint32_t>(r.bytes.size()));
    m.write(s);
    expected.push_back(std::move(r));
  }
  const std::vector<Read> got = readWithBagReader(path, topics);
  const auto reader = topics ? std::make_unique<viper::BagReader>(path, *topics) : std::make_unique<viper::BagReader>(path);
  EXPECT_EQ(reader->size(), view->size());
  EXPECT_EQ(ids(reader->connections()), ids(view->getConnections()));
  EXPECT_EQ(ids(reader->bagConnections()), ids(rosbag::View(bag).getConnections()));
  if (expected.empty()) EXPECT_TRUE(got.empty());
  else expectSameReads(path, got, expected, Ties::kAsMultiset);
}

TEST(BagReader, ReadsTheTopicsAskedForAsRosbagViewDoes) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/rosbag.bag", rosbag::compression::LZ4);
  writeWithBagWriter(dir + "/bag_writer.bag", "lz4");
  writeWithBagWriter(dir + "/bag_writer_bz2.bag", "bz2");
  for (const std::string& path : {dir + "/rosbag.bag", dir + "/bag_writer.bag", dir + "/bag_writer_bz2.bag"})
    for (const Topics& topics : {Topics(), Topics({"/camera/image"}), Topics({"/camera/info", "/late", "/latched"}),
                                 Topics({"/nothing"}), Topics(std::set<std::string>())})
      expectReadsAsRosbagView(path, topics);
  const std::string raw = VIPER_SOURCE_DIR "/bags/test_scene_raw.bag";
  for (const Topics& topics : {Topics({"/capture/draws"}), Topics({"/capture/draws", "/capture/mesh_store"})})
    expectReadsAsRosbagView(raw, topics);
}

// The typed message as rosbag's MessageInstance::instantiate gives it: equal, or null in both
// where the md5sum is another type's.
template <typename M>
void expectInstantiatedAsRosbag(const std::string& path, const std::string& topic) {
  SCOPED_TRACE(path + " " + topic);
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  viper::BagReader reader(path, {topic});
  viper::BagReadMessage m;
  size_t typed = 0;
  for (const rosbag::MessageInstance& expected : view) {
    ASSERT_TRUE(reader.next(m));
    const boost::shared_ptr<M> theirs = expected.instantiate<M>(), mine = m.instantiate<M>();
    ASSERT_EQ(mine == nullptr, theirs == nullptr);
    if (mine == nullptr) continue;
    EXPECT_TRUE(*mine == *theirs);
    ++typed;
  }
  EXPECT_FALSE(reader.next(m));
  std::cout << path << " " << topic << ": " << typed << " of " << view.size() << " as " << ros::message_traits::datatype<M>() << "\n";
}

TEST(BagReader, InstantiatesAsRosbagDoes) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeWithRosbag(dir + "/rosbag.bag", rosbag::compression::BZ2);
  writeWithBagWriter(dir + "/bag_writer.bag", "none");
  for (const std::string& path : {dir + "/rosbag.bag", dir + "/bag_writer.bag"}) {
    expectInstantiatedAsRosbag<sensor_msgs::Image>(path, "/camera/image");
    expectInstantiatedAsRosbag<std_msgs::String>(path, "/camera/image");
    expectInstantiatedAsRosbag<std_msgs::String>(path, "/latched");
    expectInstantiatedAsRosbag<sensor_msgs::Image>(path, "/latched");
  }
}

// A connection of md5sum "*" takes any type; bytes too few for the type throw ros::Exception, as
// rosbag's instantiate throws.
TEST(BagReader, AnyTypeAndTooFewBytes) {
  const std::string path = tempDir("viper_bag_reader_") + "/odd.bag";
  {
    viper::dataset::BagFileWriter bag(path);
    auto any = writerFields<std_msgs::String>();
    any["md5sum"] = "*";
    const uint32_t wildcard = bag.addConnection("/any", any);
    const uint32_t short_image = bag.addConnection("/short", writerFields<sensor_msgs::Image>());
    std_msgs::String s;
    s.data = "some text";
    put(bag, wildcard, ros::Time(1, 0), s);
    put(bag, short_image, ros::Time(2, 0), s);
    bag.close();
  }
  viper::BagReader reader(path);
  viper::BagReadMessage m;
  ASSERT_TRUE(reader.next(m));
  ASSERT_NE(m.instantiate<std_msgs::String>(), nullptr);
  EXPECT_EQ(m.instantiate<std_msgs::String>()->data, "some text");
  ASSERT_TRUE(reader.next(m));
  EXPECT_THROW(m.instantiate<sensor_msgs::Image>(), ros::Exception);
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& r : rosbag::View(bag, rosbag::TopicQuery("/short")))
    EXPECT_THROW(r.instantiate<sensor_msgs::Image>(), ros::Exception);
  EXPECT_FALSE(reader.next(m));
}

// A missing file, a text file, a damaged chunk (after the messages before it): BagReadError, its
// what() naming the file, its problem() what is wrong without the file's name.
TEST(BagReader, ErrorsNameTheFile) {
  const std::string dir = tempDir("viper_bag_reader_");
  writeFile(dir + "/text.bag", "not a bag\n");
  for (const std::string& path : {dir + "/missing.bag", dir + "/text.bag"}) {
    try {
      viper::BagReader bag(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const viper::BagReadError& e) {
      EXPECT_EQ(std::string(e.what()), path + ": " + e.problem());
      EXPECT_FALSE(e.problem().empty());
      std::cout << e.what() << "\n";
    }
  }
  writeTextBag(dir + "/intact.bag", rosbag::compression::LZ4);
  const size_t chunk = damageThirdChunk(dir + "/intact.bag", "lz4", dir + "/damaged.bag");
  ASSERT_NE(chunk, std::string::npos);
  const std::vector<Read> all = readWithRosbag(dir + "/intact.bag");
  viper::BagReader reader(dir + "/damaged.bag", {"/text"});
  viper::BagReadMessage m;
  size_t read = 0;
  try {
    while (reader.next(m)) {
      ASSERT_LT(read, all.size());
      EXPECT_EQ(std::vector<uint8_t>(m.data(), m.data() + m.size()), all[read].bytes) << "message " << read;
      ++read;
    }
    ADD_FAILURE() << "no error";
  } catch (const viper::BagReadError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(dir + "/damaged.bag: damaged chunk at byte " + std::to_string(chunk), 0), 0u)
        << e.what();
    EXPECT_EQ(e.problem().rfind("damaged chunk at byte ", 0), 0u) << e.problem();
  }
  EXPECT_GT(read, 0u);
}

std::vector<Read> ofTopic(const std::vector<Read>& all, const std::string& topic) {
  std::vector<Read> out;
  for (const Read& r : all)
    if (r.topic == topic) out.push_back(r);
  return out;
}

// A damaged chunk that holds none of the topics asked for is not read, by BagReader nor by
// BagFileReader with that selection: every message asked for comes, no error.
TEST(BagReader, ADamagedChunkOfOtherTopicsIsNotRead) {
  withDamagedChunk(writeOneMessageChunks, 4, [](const std::string& damaged, size_t chunk, const std::vector<Read>& all) {
    ASSERT_EQ(all.size(), 12u);  // the damaged chunk: /b at time 4
    const std::vector<Read> a = ofTopic(all, "/a");
    ASSERT_EQ(a.size(), 6u);
    std::string error;
    readWithReader(damaged, &error);
    EXPECT_NE(error.find("damaged chunk at byte " + std::to_string(chunk) + ": "), std::string::npos)
        << "the whole bag's reading meets it: " << error;

    EXPECT_TRUE(readWithBagReader(damaged, Topics({"/a"})) == a);
    EXPECT_EQ(viper::BagReader(damaged, {"/a"}).size(), 6u);
    const std::function<bool(const viper::dataset::BagConnection&)> only_a =
        [](const viper::dataset::BagConnection& c) { return c.topic == "/a"; };
    EXPECT_TRUE(readOnWithReader(damaged, nullptr, &only_a) == a);
    BagFileReader selected(damaged);
    selected.select(only_a);
    EXPECT_EQ(selected.messageCount(), 6u);
    EXPECT_EQ(selected.connections().size(), 2u) << "the whole bag's connections";
    viper::dataset::BagMessage m;
    ASSERT_TRUE(selected.next(m));
    EXPECT_THROW(selected.select(only_a), std::logic_error) << "a selection after next()";
  });
}

// A damaged chunk of the topics asked for: BagReadError once, naming the chunk, with its message
// skipped; the next call reads on with the next chunk's messages. BagFileReader over every topic
// the same (the damaged chunk is read ahead there, with the one before it).
TEST(BagReader, ADamagedChunkIsAnErrorOnceThenReadingGoesOn) {
  withDamagedChunk(writeOneMessageChunks, 3, [](const std::string& damaged, size_t chunk, std::vector<Read> all) {
    ASSERT_EQ(all.size(), 12u);  // the damaged chunk: /a at time 3
    std::vector<Read> a = ofTopic(all, "/a");
    ASSERT_EQ(a[1].sec, 3u);
    a.erase(a.begin() + 1);
    ASSERT_EQ(all[2].sec, 3u);
    all.erase(all.begin() + 2);

    viper::BagReader reader(damaged, {"/a"});
    viper::BagReadMessage m;
    std::vector<Read> got;
    size_t errors = 0;
    for (;;) {
      try {
        if (!reader.next(m)) break;
        got.push_back({m.topic(), m.time().sec, m.time().nsec, m.connection().fields, {m.data(), m.data() + m.size()}});
      } catch (const viper::BagReadError& e) {
        ++errors;
        EXPECT_EQ(got.size(), 1u) << "after the message before it";
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(damaged + ": damaged chunk at byte " + std::to_string(chunk) + ": ", 0), 0u) << what;
        EXPECT_NE(what.find("(1 message skipped)"), std::string::npos) << what;
        ASSERT_EQ(e.skipped().size(), 1u);
        EXPECT_EQ(e.skipped()[0].topic(), "/a");
        EXPECT_EQ(e.skipped()[0].time, ros::Time(3, 0));
        ASSERT_LT(errors, 5u);
      }
    }
    EXPECT_EQ(errors, 1u);
    EXPECT_TRUE(got == a);

    std::vector<viper::dataset::BagDamagedChunk> damages;
    EXPECT_TRUE(readOnWithReader(damaged, &damages) == all);
    ASSERT_EQ(damages.size(), 1u);
    EXPECT_EQ(damages[0].position(), chunk);
    ASSERT_EQ(damages[0].skipped().size(), 1u);
    EXPECT_EQ(damages[0].skipped()[0].sec, 3u);
  });
}

}  // namespace
