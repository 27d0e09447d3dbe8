// The package's own bag readers against rosbag::View, reading intact bags: dataset::BagFileReader
// (bag_player's) on bags written by rosbag's C++ writer and by BagFileWriter with each compression,
// several topics and chunks that overlap in time, and on the committed test bag: every message comes
// back with its topic, time, connection header and bytes, in rosbag's order; a bulk sink gets large
// messages' bulk as rosbag reads it. Then viper::BagReader, the typed reader over it (generate's and
// the tools'), against rosbag::View with a TopicQuery and MessageInstance::instantiate. Damaged bags:
// test_bag_reader_damage.cpp.
#include "bag_reader_test_support.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace {

using viper::dataset::BagFileReader;
using viper::test::tempDir;

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
  for (const rosbag::MessageInstance& m : *view) expected.push_back(readOf(m));
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

}  // namespace
