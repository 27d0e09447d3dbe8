// rostest tester for capture_bridge: reads the same capture itself, subscribes to every topic of the
// bridge and checks that each intact frame arrives once on every topic with one shared stamp, with
// the right sizes, encodings and contents (color and draw ids byte-equal to the capture, finite depth
// where a draw owns the pixel, primitive ids within their draw's primitive count, -1 elsewhere).
//
// Private parameters: capture (path, required), frame_id (default camera_optical), timeout_s (60),
// expect_damage (false: when true, also expects the bridge's ERROR log on /rosout naming the capture
// and checks that ~bridge_node is still alive afterwards), follow (false; true: the capture is still
// being written, read it to its end marker), subscribe_after_s (0: subscribe only after this many
// seconds, like a node that starts late).
#include "tester_main.h"
#include "viper/capture/capture_stream.h"
#include "viper/capture/content_key.h"
#include "viper/ros/conversions/frame_conversions.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <set>

namespace viper {
namespace {

struct ExpectedFrame {
  uint64_t number = 0;
  double time_s = 0.0;
  uint32_t width = 0, height = 0;
  uint64_t color_key = 0, draw_ids_key = 0;
  bool has_camera = false;
  std::set<uint64_t> mesh_keys;
};

struct ReceivedFrame {
  int color = 0, color_info = 0, depth = 0, depth_info = 0, draw_ids = 0, primitive_ids = 0, draws = 0;
  uint64_t color_key = 0, draw_ids_key = 0, number = 0;
  // Kept until the cross-image checks ran, then freed.
  std::vector<float> depth_m;
  std::vector<int32_t> ids, primitives;
  std::vector<uint32_t> primitive_counts;  // per draw index, from the draw list
  bool depth_checked = false, primitives_checked = false;
  bool calibrated = false;
  std::vector<std::string> problems;

  bool complete() const {
    return color > 0 && color_info > 0 && depth > 0 && depth_info > 0 && draw_ids > 0 && primitive_ids > 0 &&
           draws > 0;
  }
};

class BridgeTester : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(pnh_.getParam("capture", capture_)) << "tester needs ~capture";
    pnh_.param("frame_id", frame_id_, std::string("camera_optical"));
    pnh_.param("timeout_s", timeout_s_, 60.0);
    pnh_.param("expect_damage", expect_damage_, false);
    pnh_.param("bridge_node", bridge_node_, std::string());
    pnh_.param("follow", follow_, false);
    double subscribe_after_s = 0.0;
    pnh_.param("subscribe_after_s", subscribe_after_s, 0.0);
    if (subscribe_after_s > 0.0) ros::WallDuration(subscribe_after_s).sleep();

    // Listen to the bridge's log (/rosout directly: rostest may run without the rosout aggregator)
    // before the bridge can start, which it does only once our image subscriptions exist.
    rosout_sub_ = nh_.subscribe("/rosout", 1000, &BridgeTester::onLog, this);
    if (expect_damage_) {
      // Our own /rosout publisher counts as one; the bridge's is the second.
      EXPECT_TRUE(waitFor([this] { return rosout_sub_.getNumPublishers() >= 2; }, 20.0))
          << "the bridge's /rosout publisher never connected";
    }

    const uint32_t q = 1000;
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("color/image_raw", q, [this](const auto& m) { onColor(*m); }));
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("depth/image_raw", q, [this](const auto& m) { onDepth(*m); }));
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("draw_ids", q, [this](const auto& m) { onDrawIds(*m); }));
    subs_.push_back(
        nh_.subscribe<sensor_msgs::Image>("primitive_ids", q, [this](const auto& m) { onPrimitiveIds(*m); }));
    subs_.push_back(nh_.subscribe<sensor_msgs::CameraInfo>("color/camera_info", q,
                                                          [this](const auto& m) { onInfo(*m, true); }));
    subs_.push_back(nh_.subscribe<sensor_msgs::CameraInfo>("depth/camera_info", q,
                                                          [this](const auto& m) { onInfo(*m, false); }));
    subs_.push_back(nh_.subscribe<DrawList>("draws", q, [this](const auto& m) { onDraws(*m); }));
    subs_.push_back(nh_.subscribe<MeshStore>("mesh_store", q, [this](const auto& m) { onMeshStore(*m); }));
  }

  /// Reads the capture's intact frames; with ~follow, waits for a writer to finish the file.
  void readExpected() {
    std::unique_ptr<CaptureReader> reader;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s_);
    while (!reader) {
      try {
        reader = std::make_unique<CaptureReader>(capture_);
      } catch (const std::exception& e) {
        if (!follow_ || ros::WallTime::now() > deadline) throw;
        ros::WallDuration(0.02).sleep();
      }
    }
    CaptureFrame f;
    try {
      CaptureReader::Status status;
      while ((status = reader->next(f, follow_)) != CaptureReader::Status::kEnd) {
        if (status == CaptureReader::Status::kPending) {
          if (ros::WallTime::now() > deadline) throw std::runtime_error("capture never ended: " + capture_);
          ros::WallDuration(0.02).sleep();
          continue;
        }
        if (!validateFrame(f).empty()) continue;
        ExpectedFrame e;
        e.number = f.number;
        e.time_s = f.time_s;
        e.width = f.width;
        e.height = f.height;
        e.color_key = contentKey(f.color_rgb.data(), f.color_rgb.size());
        e.draw_ids_key = contentKey(f.draw_ids.data(), f.draw_ids.size() * 4);
        e.has_camera = chooseFrameCamera(f).has_value();
        for (const DrawRecord& d : f.draws) e.mesh_keys.insert(d.mesh_key);
        expected_.push_back(e);
      }
    } catch (const CaptureFormatError& e) {
      damaged_ = true;
    }
  }

  template <typename Pred>
  bool waitFor(Pred done, double timeout_s) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      ros::spinOnce();
      if (done()) return true;
      ros::WallDuration(0.01).sleep();
    }
    ros::spinOnce();
    return done();
  }

  ReceivedFrame& frameOf(const std_msgs::Header& h) {
    ReceivedFrame& r = received_[h.stamp];
    if (h.frame_id != frame_id_) r.problems.push_back("frame_id '" + h.frame_id + "'");
    return r;
  }

  void checkImage(ReceivedFrame& r, const sensor_msgs::Image& m, const std::string& encoding, uint32_t bytes) {
    if (m.encoding != encoding) r.problems.push_back("encoding " + m.encoding + " instead of " + encoding);
    if (m.step != m.width * bytes || m.data.size() != size_t(m.step) * m.height) {
      r.problems.push_back(encoding + " image step/size mismatch");
    }
    if (m.width != expected_.front().width || m.height != expected_.front().height) {
      r.problems.push_back(encoding + " image size " + std::to_string(m.width) + "x" + std::to_string(m.height));
    }
  }

  // Cross-image checks of one frame, run once their inputs have all arrived.
  void crossCheck(ReceivedFrame& r) {
    if (!r.depth_checked && !r.depth_m.empty() && !r.ids.empty()) {
      size_t bad = 0;
      for (size_t i = 0; i < r.ids.size() && i < r.depth_m.size(); ++i) {
        if (r.ids[i] != 0 && !(std::isfinite(r.depth_m[i]) && r.depth_m[i] > 0)) ++bad;
      }
      if (bad) r.problems.push_back(std::to_string(bad) + " pixels with a draw id but no finite depth");
      r.depth_checked = true;
    }
    if (!r.primitives_checked && !r.primitives.empty() && !r.ids.empty() && r.draws > 0) {
      size_t bad = 0;
      for (size_t i = 0; i < r.ids.size() && i < r.primitives.size(); ++i) {
        const int32_t id = r.ids[i], prim = r.primitives[i];
        const bool ok = id == 0 ? prim == -1
                                : id > 0 && size_t(id) <= r.primitive_counts.size() && prim >= 0 &&
                                      uint32_t(prim) < r.primitive_counts[id - 1];
        if (!ok) ++bad;
      }
      if (bad) r.problems.push_back(std::to_string(bad) + " pixels whose primitive id is not a primitive of their draw");
      r.primitives_checked = true;
    }
    if (r.depth_checked && r.primitives_checked) {
      r.depth_m = {};
      r.ids = {};
      r.primitives = {};
    }
  }

  void onColor(const sensor_msgs::Image& m) {
    ReceivedFrame& r = frameOf(m.header);
    ++r.color;
    checkImage(r, m, sensor_msgs::image_encodings::RGB8, 3);
    r.color_key = contentKey(m.data.data(), m.data.size());
  }
  // An image of 4-byte pixels that the cross-check reads: counted in `count`, checked as `encoding`,
  // its pixels copied into `pixels`. Returns its frame.
  template <typename T>
  ReceivedFrame& onPixels(const sensor_msgs::Image& m, int ReceivedFrame::*count, const std::string& encoding,
                          std::vector<T> ReceivedFrame::*pixels) {
    ReceivedFrame& r = frameOf(m.header);
    ++(r.*count);
    checkImage(r, m, encoding, 4);
    std::vector<T>& to = r.*pixels;
    to.resize(m.data.size() / 4);
    std::memcpy(to.data(), m.data.data(), to.size() * 4);
    return r;
  }
  void onDepth(const sensor_msgs::Image& m) {
    crossCheck(onPixels(m, &ReceivedFrame::depth, sensor_msgs::image_encodings::TYPE_32FC1, &ReceivedFrame::depth_m));
  }
  void onDrawIds(const sensor_msgs::Image& m) {
    ReceivedFrame& r = onPixels(m, &ReceivedFrame::draw_ids, sensor_msgs::image_encodings::TYPE_32SC1, &ReceivedFrame::ids);
    r.draw_ids_key = contentKey(m.data.data(), m.data.size());
    crossCheck(r);
  }
  void onPrimitiveIds(const sensor_msgs::Image& m) {
    crossCheck(onPixels(m, &ReceivedFrame::primitive_ids, sensor_msgs::image_encodings::TYPE_32SC1,
                        &ReceivedFrame::primitives));
  }
  void onInfo(const sensor_msgs::CameraInfo& m, bool color) {
    ReceivedFrame& r = frameOf(m.header);
    ++(color ? r.color_info : r.depth_info);
    r.calibrated = m.K[0] > 0 && m.K[4] > 0 && m.K[8] == 1;
    if (m.width != expected_.front().width || m.height != expected_.front().height) {
      r.problems.push_back("camera_info size");
    }
  }
  void onDraws(const DrawList& m) {
    ReceivedFrame& r = frameOf(m.header);
    ++r.draws;
    r.number = m.frame_number;
    r.primitive_counts.assign(m.draws.size(), 0);
    for (const Draw& d : m.draws) {
      draw_mesh_keys_.insert(d.mesh_key);
      if (d.index < m.draws.size()) r.primitive_counts[d.index] = d.primitive_count;
    }
    crossCheck(r);
  }
  void onMeshStore(const MeshStore& m) {
    ++mesh_store_messages_;
    for (const Mesh& mesh : m.meshes) {
      store_keys_.insert(mesh.key);
      if (mesh.indices.empty() || mesh.positions_xyz.size() % 3 != 0) bad_meshes_.insert(mesh.key);
    }
  }
  void onLog(const rosgraph_msgs::Log& m) {
    if (m.level >= rosgraph_msgs::Log::ERROR && m.msg.find(capture_) != std::string::npos) {
      error_logs_.push_back(m.name + ": " + m.msg);
    }
  }

  size_t completeFrames() const {
    size_t n = 0;
    for (const auto& [stamp, r] : received_) n += r.complete() ? 1 : 0;
    return n;
  }
  bool storeHoldsAllKeys() const {
    for (uint64_t k : draw_mesh_keys_) {
      if (!store_keys_.count(k)) return false;
    }
    return true;
  }

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_{"~"};
  std::string capture_, frame_id_, bridge_node_;
  double timeout_s_ = 60.0;
  bool expect_damage_ = false;
  bool follow_ = false;
  bool damaged_ = false;
  std::vector<ExpectedFrame> expected_;
  std::map<ros::Time, ReceivedFrame> received_;
  std::set<uint64_t> draw_mesh_keys_, store_keys_, bad_meshes_;
  int mesh_store_messages_ = 0;
  std::vector<std::string> error_logs_;
  ros::Subscriber rosout_sub_;
  std::vector<ros::Subscriber> subs_;
};

TEST_F(BridgeTester, EveryFrameOnEveryTopicWithOneStamp) {
  // Subscribed already: with ~follow the bridge publishes while the capture is still being written.
  readExpected();
  ASSERT_FALSE(expected_.empty()) << capture_ << " holds no intact frame";
  ASSERT_EQ(damaged_, expect_damage_) << capture_ << (damaged_ ? " is damaged" : " is intact");

  const bool arrived = waitFor(
      [this] {
        return completeFrames() >= expected_.size() && storeHoldsAllKeys() &&
               (!expect_damage_ || !error_logs_.empty());
      },
      timeout_s_);
  EXPECT_TRUE(arrived) << completeFrames() << " of " << expected_.size() << " frames complete, "
                       << error_logs_.size() << " error logs, mesh store " << store_keys_.size() << " keys";

  // One stamp per frame: every message of a frame shares it, so the count of stamps is the frame count.
  ASSERT_EQ(received_.size(), expected_.size());
  size_t i = 0;
  double first_stamp = 0.0;
  for (const auto& [stamp, r] : received_) {
    const ExpectedFrame& e = expected_[i];
    SCOPED_TRACE("frame " + std::to_string(e.number) + " stamp " + std::to_string(stamp.toSec()));
    EXPECT_EQ(r.color, 1);
    EXPECT_EQ(r.color_info, 1);
    EXPECT_EQ(r.depth, 1);
    EXPECT_EQ(r.depth_info, 1);
    EXPECT_EQ(r.draw_ids, 1);
    EXPECT_EQ(r.primitive_ids, 1);
    EXPECT_EQ(r.draws, 1);
    EXPECT_EQ(r.number, e.number);  // in capture order
    EXPECT_EQ(r.color_key, e.color_key) << "color differs from the capture";
    // The image's int32 ids hold the capture's uint32 ids byte for byte.
    EXPECT_EQ(r.draw_ids_key, e.draw_ids_key) << "draw ids differ from the capture";
    EXPECT_EQ(r.calibrated, e.has_camera);
    EXPECT_TRUE(r.depth_checked && r.primitives_checked);
    for (const std::string& p : r.problems) ADD_FAILURE() << p;
    if (i == 0) first_stamp = stamp.toSec();
    // Stamps follow capture time (1 microsecond: ros::Time resolution after float rounding).
    EXPECT_NEAR(stamp.toSec() - first_stamp, e.time_s - expected_.front().time_s, 1e-6);
    ++i;
  }
  EXPECT_GE(mesh_store_messages_, 1);
  EXPECT_TRUE(storeHoldsAllKeys()) << "mesh_store lacks meshes referenced by draws";
  EXPECT_TRUE(bad_meshes_.empty());

  if (expect_damage_) {
    EXPECT_FALSE(error_logs_.empty()) << "no ERROR log naming " << capture_;
    if (!bridge_node_.empty()) {
      EXPECT_TRUE(ros::service::waitForService(bridge_node_ + "/get_loggers", ros::Duration(60.0)))
          << bridge_node_ << " died after the damaged frame";
    }
  }
}

}  // namespace
}  // namespace viper

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "capture_bridge_tester");
}
