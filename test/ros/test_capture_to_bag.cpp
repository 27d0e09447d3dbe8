// The capture_to_bag command (no roscore): on make_test_capture's captures, the bag holds the raw
// topics as the bridge's conversion (viper::frameMessages, ReplayTiming) builds them, in the bridge's
// order, each written at its header stamp, the mesh store latched; a truncated capture keeps its
// intact frames, is named with the byte offset of the damage and ends with exit status 1; bad usage
// prints the usage and exits 2. capture_to_bag.test compares the bag with the running bridge.
#include "../common/temp_dir.h"
#include "message_bytes.h"

#include "viper/capture/capture_stream.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/pacing/replay_timing.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class CaptureToBagTest : public testing::Test {
 protected:
  Result run(const std::string& args) {
    const fs::path out = work_ / "stdout.txt", err = work_ / "stderr.txt";
    const std::string command = std::string(VIPER_CAPTURE_TO_BAG) + " " + args + " > " + out.string() + " 2> " + err.string();
    const int status = std::system(command.c_str());
    Result r;
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  viper::test::TempDir work_{"viper_capture_to_bag_"};
};

struct Expected {
  std::string topic;
  ros::Time stamp;
  std::vector<uint8_t> bytes;
};

// The messages the bridge builds for the first `max_frames` frames of `capture`, in publication order.
std::vector<Expected> bridgeMessages(const std::string& capture, size_t max_frames, const std::string& ns) {
  viper::CaptureReader reader(capture);
  viper::ReplayTiming timing(0.0, std::nullopt);
  viper::MeshStoreAccumulator meshes;
  viper::CaptureFrame frame;
  std::vector<Expected> out;
  uint32_t stores = 0;
  for (size_t n = 0; n < max_frames && reader.next(frame) == viper::CaptureReader::Status::kFrame; ++n) {
    std_msgs::Header header;
    header.stamp = ros::Time(timing.stampOf(frame.time_s));
    header.frame_id = "camera_optical";
    viper::FrameMessages m = viper::frameMessages(frame, header, meshes);
    // What a subscriber of the bridge receives: roscpp numbers each publisher's messages in header.seq.
    for (auto* h : {&m.color->header, &m.camera_info->header, &m.depth->header, &m.draw_ids->header,
                    &m.primitive_ids->header, &m.draws->header})
      h->seq = static_cast<uint32_t>(n);
    if (m.mesh_store) {
      m.mesh_store->header.seq = stores++;
      out.push_back({ns + "/mesh_store", header.stamp, viper::test::serialized(*m.mesh_store)});
    }
    out.push_back({ns + "/color/image_raw", header.stamp, viper::test::serialized(*m.color)});
    out.push_back({ns + "/color/camera_info", header.stamp, viper::test::serialized(*m.camera_info)});
    out.push_back({ns + "/depth/image_raw", header.stamp, viper::test::serialized(*m.depth)});
    out.push_back({ns + "/depth/camera_info", header.stamp, viper::test::serialized(*m.camera_info)});
    out.push_back({ns + "/draw_ids", header.stamp, viper::test::serialized(*m.draw_ids)});
    out.push_back({ns + "/primitive_ids", header.stamp, viper::test::serialized(*m.primitive_ids)});
    out.push_back({ns + "/draws", header.stamp, viper::test::serialized(*m.draws)});
  }
  return out;
}

// Compares the bag with `expected`, topic by topic in order (a view orders messages by time only, and
// the messages of one frame share their time).
void expectBagHolds(const std::string& bag_path, const std::vector<Expected>& expected) {
  std::map<std::string, std::vector<const Expected*>> by_topic;
  for (const Expected& e : expected) by_topic[e.topic].push_back(&e);
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View all(bag);
  EXPECT_EQ(all.size(), expected.size());
  std::set<std::string> topics;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) topics.insert(c->topic);
  EXPECT_EQ(topics.size(), by_topic.size());
  for (const auto& [topic, messages] : by_topic) {
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    ASSERT_EQ(view.size(), messages.size()) << topic;
    size_t i = 0;
    for (const rosbag::MessageInstance& m : view) {
      const Expected& e = *messages[i++];
      EXPECT_EQ(m.getTime(), e.stamp) << topic << " is written at its header stamp";
      EXPECT_TRUE(viper::test::heldBytes(m) == e.bytes) << topic << " stamped " << e.stamp << " differs";
      const auto& header = *m.getConnectionHeader();
      EXPECT_EQ(header.at("latching"), topic == "/capture/mesh_store" ? "1" : "0") << topic;
      EXPECT_EQ(header.at("type"), m.getDataType());
    }
  }
  EXPECT_GE(by_topic["/capture/mesh_store"].size(), 1u);
}

TEST_F(CaptureToBagTest, WritesTheBridgesMessagesForEveryFrame) {
  const std::string bag = work_ / "ok.bag";
  const Result r = run(std::string(VIPER_TEST_CAPTURE_OK) + " --output " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote 8 frames"), std::string::npos) << r.out;
  expectBagHolds(bag, bridgeMessages(VIPER_TEST_CAPTURE_OK, 1000, "/capture"));
}

TEST_F(CaptureToBagTest, FramesLimitsTheFramesAndCompressionIsChosen) {
  const std::string bag = work_ / "three.bag";
  const Result r = run(std::string(VIPER_TEST_CAPTURE_OK) + " --frames 3 --compression bz2 --output " + bag);
  ASSERT_EQ(r.status, 0) << r.err;
  expectBagHolds(bag, bridgeMessages(VIPER_TEST_CAPTURE_OK, 3, "/capture"));
  rosbag::Bag b(bag, rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(b, rosbag::TopicQuery("/capture/draws")).size(), 3u);
}

TEST_F(CaptureToBagTest, TruncatedCaptureKeepsTheIntactFramesAndNamesFileFrameAndOffset) {
  // What a reader gets from the capture before the damage, and where the damage is.
  size_t intact = 0;
  uint64_t damage_offset = 0, last_number = 0;
  {
    viper::CaptureReader reader(VIPER_TEST_CAPTURE_TRUNCATED);
    viper::CaptureFrame frame;
    try {
      while (reader.next(frame) == viper::CaptureReader::Status::kFrame) {
        ++intact;
        last_number = frame.number;
      }
      FAIL() << "the truncated capture reads to its end";
    } catch (const viper::CaptureFormatError& e) {
      damage_offset = e.offset();
    }
  }
  ASSERT_GE(intact, 1u);
  const std::string bag = work_ / "truncated.bag";
  const Result r = run(std::string(VIPER_TEST_CAPTURE_TRUNCATED) + " --output " + bag);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find(VIPER_TEST_CAPTURE_TRUNCATED), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("damaged at byte " + std::to_string(damage_offset)), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("after frame " + std::to_string(last_number)), std::string::npos) << r.err;
  expectBagHolds(bag, bridgeMessages(VIPER_TEST_CAPTURE_TRUNCATED, intact, "/capture"));
}

TEST_F(CaptureToBagTest, BadUsagePrintsUsage) {
  const std::string ok = VIPER_TEST_CAPTURE_OK;
  for (const std::string& args : std::vector<std::string>{"", ok, "--output x.bag",
                                                          ok + " --output x.bag --compression zip",
                                                          ok + " --output x.bag --frames 0",
                                                          ok + " --output x.bag --bogus 1"}) {
    const Result r = run(args);
    EXPECT_EQ(r.status, 2) << "'" << args << "'";
    EXPECT_NE(r.err.find("usage: capture_to_bag"), std::string::npos) << "'" << args << "': " << r.err;
  }
  const Result missing = run((work_ / "missing.vcap") + " --output " + (work_ / "m.bag"));
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("missing.vcap"), std::string::npos) << missing.err;
}

}  // namespace
