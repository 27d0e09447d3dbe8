// The package's own bag writer (BagWriter on dataset::BagFileWriter) against rosbag, the reader every
// user has: with each compression, every message comes back from rosbag's C++ reader and from
// Python's rosbag (an independent implementation) with its topic, stamp, type, md5sum, connection
// header and bytes; LZ4 chunks that do not compress are stored plain and still read; `rosbag
// reindex` (which walks the records one by one, not through the index) rebuilds the same index;
// an unwritable path or a message at time 0 is a clear error.
#include "viper/ros/bridge/bag_writer.h"

#include "../common/process_util.h"
#include "message_bytes.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <topic_tools/shape_shifter.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <random>
#include <vector>

namespace {

using viper::test::readFile;
using viper::test::run;
using viper::test::tempDir;

struct Written {
  std::string topic;
  ros::Time time;
  std::vector<uint8_t> bytes;
  std::string type;
  bool latched;
};

// 12 frames of a 640x360 image pair (one compresses 100:1, one is noise), a small image and a
// latched transform, interleaved as a frame's topics are.
std::vector<Written> writeBag(const std::string& path, const std::string& compression) {
  std::vector<Written> written;
  viper::BagWriter bag(path, compression, "/test_bag_writer");
  std::mt19937 random(7);
  for (uint32_t f = 0; f < 12; ++f) {
    const ros::Time t(1, 66666667u * f + 1);
    auto image = [&](uint32_t w, uint32_t h, bool noise) {
      auto m = boost::make_shared<sensor_msgs::Image>();
      m->header.stamp = t;
      m->header.frame_id = "camera_optical";
      m->width = w, m->height = h, m->encoding = "32FC2", m->step = w * 8;
      m->data.resize(static_cast<size_t>(m->step) * h);
      for (size_t i = 0; i < m->data.size(); ++i) m->data[i] = noise ? static_cast<uint8_t>(random()) : (i / 4096) % 7;
      return m;
    };
    for (const auto& [topic, m] : {std::pair{"/ground_truth/semantic", image(640, 360, false)},
                                   std::pair{"/ground_truth/flow/forward", image(640, 360, true)},
                                   std::pair{"/small", image(8, 2, false)}}) {
      bag.write(topic, m);
      written.push_back({topic, t, viper::test::serialized(*m), "sensor_msgs/Image", false});
    }
    if (f % 5 == 0) {
      auto tf = boost::make_shared<tf2_msgs::TFMessage>();
      tf->transforms.resize(1);
      tf->transforms[0].header.stamp = t;
      tf->transforms[0].child_frame_id = "frame " + std::to_string(f);
      bag.writeAt("/tf_static", t, tf, /*latched=*/true);
      written.push_back({"/tf_static", t, viper::test::serialized(*tf), "tf2_msgs/TFMessage", true});
    }
  }
  bag.close();
  return written;
}

void expectSameMessages(const std::string& path, const std::vector<Written>& written) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  // rosbag returns them by time (ties in its own order): compared by time, then topic.
  auto order = [](const Written& a, const Written& b) { return a.time != b.time ? a.time < b.time : a.topic < b.topic; };
  std::vector<Written> sorted = written, read;
  std::sort(sorted.begin(), sorted.end(), order);
  for (const rosbag::MessageInstance& m : view) {
    read.push_back({m.getTopic(), m.getTime(), viper::test::heldBytes(m), m.getDataType(), m.isLatching()});
    EXPECT_EQ(m.getCallerId(), "/test_bag_writer");
    if (m.getDataType() == "sensor_msgs/Image") {
      EXPECT_EQ(m.getMD5Sum(), ros::message_traits::md5sum<sensor_msgs::Image>());
      EXPECT_EQ(m.getMessageDefinition(), ros::message_traits::definition<sensor_msgs::Image>());
    }
  }
  std::sort(read.begin(), read.end(), order);
  ASSERT_EQ(read.size(), sorted.size());
  for (size_t i = 0; i < read.size(); ++i) {
    const Written& w = sorted[i];
    const Written& m = read[i];
    EXPECT_EQ(m.topic, w.topic);
    EXPECT_EQ(m.time, w.time);
    EXPECT_EQ(m.type, w.type);
    EXPECT_EQ(m.latched, w.latched) << w.topic;
    EXPECT_TRUE(m.bytes == w.bytes) << w.topic << " at " << w.time << ": bytes differ";
  }
}

TEST(BagWriter, RosbagReadsEveryMessageWithEachCompression) {
  for (const char* compression : {"none", "lz4", "bz2"}) {
    SCOPED_TRACE(compression);
    const std::string path = tempDir("viper_bag_writer_") + "/" + compression + ".bag";
    const std::vector<Written> written = writeBag(path, compression);
    expectSameMessages(path, written);
  }
}

// The file is written around the page cache (O_DIRECT) where the file system allows it; tmpfs
// refuses O_DIRECT, and the same bytes are then written through the cache.
TEST(BagWriter, SameBagOnAFileSystemWithoutDirectWrites) {
  if (!std::filesystem::is_directory("/dev/shm")) GTEST_SKIP() << "no /dev/shm (tmpfs) here";
  const std::string on_disk = tempDir("viper_bag_writer_") + "/disk.bag";
  const std::string on_tmpfs = "/dev/shm/viper_test_bag_writer_" + std::to_string(::getpid()) + ".bag";
  writeBag(on_disk, "lz4");
  const std::vector<Written> written = writeBag(on_tmpfs, "lz4");
  expectSameMessages(on_tmpfs, written);
  const std::string a = readFile(on_disk), b = readFile(on_tmpfs);
  std::filesystem::remove(on_tmpfs);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "the same bytes either way";
}

TEST(BagWriter, Lz4BagStoresWhatDoesNotCompressAndPythonReadsIt) {
  const std::string dir = tempDir("viper_bag_writer_");
  const std::string path = dir + "/python.bag";
  const std::vector<Written> written = writeBag(path, "lz4");
  const std::string log = dir + "/info.log";
  // rosbag info's YAML (Python's rosbag) counts chunks by compression, and reading every message
  // checks every LZ4 frame's checksum.
  ASSERT_EQ(run("/usr/bin/python3 -c \"import rosbag,sys; b=rosbag.Bag(sys.argv[1]); "
                "n=sum(1 for _ in b.read_messages()); i=b.get_compression_info(); "
                "print('messages', n, 'compression', i.compression); "
                "import collections; c=collections.Counter(h.compression for h in b._chunk_headers.values()); "
                "print('chunks', dict(c))\" " + path + " > " + log + " 2>&1"),
            0)
      << readFile(log);
  const std::string out = readFile(log);
  EXPECT_NE(out.find("messages " + std::to_string(written.size())), std::string::npos) << out;
  EXPECT_NE(out.find("'lz4': "), std::string::npos) << "compressible chunks in LZ4: " << out;
  EXPECT_NE(out.find("'none': 12"), std::string::npos) << "one plain chunk per noise image: " << out;
}

TEST(BagWriter, ReindexRebuildsTheSameIndex) {
  const std::string dir = tempDir("viper_bag_writer_");
  const std::string path = dir + "/reindex.bag";
  const std::vector<Written> written = writeBag(path, "lz4");
  // A copy without its index (connection and chunk info records cut off, as a recorder that died
  // leaves a bag), which reindex rebuilds from the chunks alone.
  const std::string copy = dir + "/reindexed.bag";
  std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
  const std::string log = dir + "/reindex.log";
  ASSERT_EQ(run("/usr/bin/python3 -c \"import rosbag,os,sys; b=rosbag.Bag(sys.argv[1]); p=b._index_data_pos; b.close(); "
                "os.truncate(sys.argv[1], p)\" " + copy + " > " + log + " 2>&1"),
            0)
      << readFile(log);
  ASSERT_EQ(run("cd " + dir + " && /usr/bin/python3 /usr/bin/rosbag reindex --force reindexed.bag > " + log + " 2>&1"), 0)
      << readFile(log);
  expectSameMessages(copy, written);
  ASSERT_EQ(run("/usr/bin/python3 /usr/bin/rosbag info --yaml " + path + " | grep -v '^path' > " + dir + "/a.yaml && " +
                "/usr/bin/python3 /usr/bin/rosbag info --yaml " + copy + " | grep -v '^path' > " + dir + "/b.yaml"),
            0);
  EXPECT_EQ(readFile(dir + "/a.yaml"), readFile(dir + "/b.yaml"));
}

TEST(BagWriter, ErrorsNameTheFile) {
  const std::string path = tempDir("viper_bag_writer_") + "/no/such/folder/x.bag";
  try {
    viper::BagWriter bag(path, "lz4", "/t");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": cannot write bag: No such file or directory"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(viper::BagWriter(tempDir("viper_bag_writer_") + "/z.bag", "zstd", "/t"), std::invalid_argument);
  viper::BagWriter bag(tempDir("viper_bag_writer_") + "/zero.bag", "none", "/t");
  auto m = boost::make_shared<sensor_msgs::Image>();
  EXPECT_THROW(bag.write("/image", m), std::invalid_argument) << "rosbag reads no message at time 0";
}

}  // namespace
