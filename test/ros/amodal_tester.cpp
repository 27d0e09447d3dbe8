// Replays a raw bag into replay.launch's nodelets (instances, amodal, ...) frame by frame and checks
// the amodal node against the instances node: before anyone listens it reads none of its frame
// inputs (nothing subscribes to instance_ids); each frame gets amodal/objects with one entry for
// every tracked object the instances node shows, each object's visible pixels (instance_ids equal
// to its track id) all inside its mask, visible_pixels their count, amodal_pixels the mask's, the
// box the mask's tight box, the fractions in [0, 1], occlusion and difficulty those of
// docs/amodal.md's thresholds; amodal/overlay black where no mask is, each visible pixel off the
// hatch stripes in its object's colour, each occluded pixel on them hatched; after the last
// subscriber leaves, the node lets its inputs go.
// Private parameters: bag (path, required), timeout_s (120; TesterBag).
#include "tester_main.h"
#include "bag_publishers.h"

#include "viper/ros/conversions/amodal_conversions.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <viper/AmodalInstanceArray.h>
#include <viper/ObjectArray.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <set>

namespace {

const std::string kAmodal = "/ground_truth/amodal/objects", kOverlay = "/ground_truth/amodal/overlay",
                  kInstances = "/ground_truth/instance_ids", kObjects = "/ground_truth/objects";

// Nodes subscribed to `topic`, as the master has them.
std::set<std::string> subscribersOf(const std::string& topic) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  std::set<std::string> nodes;
  if (!ros::master::execute("getSystemState", args, result, payload, true)) return nodes;
  XmlRpc::XmlRpcValue& subs = payload[1];
  for (int i = 0; i < subs.size(); ++i)
    if (static_cast<std::string>(subs[i][0]) == topic)
      for (int k = 0; k < subs[i][1].size(); ++k) nodes.insert(static_cast<std::string>(subs[i][1][k]));
  return nodes;
}

int expectedOcclusion(uint32_t visible, uint32_t amodal) {
  if (amodal == 0) return viper::AmodalInstance::OCCLUSION_UNKNOWN;
  const double f = double(visible) / amodal;
  return f >= 0.99 ? 0 : f >= 0.5 ? 1 : 2;
}

int expectedDifficulty(uint32_t height, int occlusion, double truncation) {
  if (height >= 40 && occlusion == 0 && truncation <= 0.15) return viper::AmodalInstance::DIFFICULTY_EASY;
  if (height >= 25 && occlusion <= 1 && truncation <= 0.30) return viper::AmodalInstance::DIFFICULTY_MODERATE;
  if (height >= 25 && occlusion <= 2 && truncation <= 0.50) return viper::AmodalInstance::DIFFICULTY_HARD;
  return viper::AmodalInstance::DIFFICULTY_IGNORED;
}

class AmodalReplay : public testing::Test {
 protected:
  std::mutex mutex_;
  std::map<ros::Time, viper::AmodalInstanceArray::ConstPtr> amodal_;
  std::map<ros::Time, viper::ObjectArray::ConstPtr> objects_;
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> images_;

  bool has(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return amodal_.count(t) && objects_.count(t) && images_[kInstances].count(t) && images_[kOverlay].count(t);
  }
};

TEST_F(AmodalReplay, MasksHoldEveryVisiblePixel) {
  ros::NodeHandle nh;
  viper::test::TesterBag bag(nh);
  rosbag::View& view = *bag.view;
  std::map<std::string, ros::Publisher>& pubs = bag.pubs;
  const ros::WallTime deadline = bag.deadline;
  ASSERT_TRUE(viper::test::waitFor([] { return viper::test::allAdvertised({kAmodal, kOverlay, kInstances}); }, deadline))
      << kAmodal << " and " << kOverlay << " never advertised";
  // Nobody listens: the amodal node (the only reader of instance_ids in this launch while nobody
  // asks for the labelled cloud) takes none of its frame inputs.
  ros::WallDuration(1.0).sleep();
  EXPECT_TRUE(subscribersOf(kInstances).empty()) << "amodal reads instance_ids unasked";

  ros::AsyncSpinner spinner(2);
  spinner.start();
  std::vector<ros::Subscriber> subs;
  // Only the objects output first: the node subscribes for it alone.
  subs.push_back(nh.subscribe<viper::AmodalInstanceArray>(kAmodal, 100, [this](const viper::AmodalInstanceArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    amodal_[m->header.stamp] = m;
  }));
  EXPECT_TRUE(viper::test::waitFor([] { return !subscribersOf(kInstances).empty(); }, deadline))
      << "amodal did not subscribe to instance_ids for its objects output";
  for (const std::string& t : {kOverlay, kInstances})
    subs.push_back(nh.subscribe<sensor_msgs::Image>(t, 100, [this, t](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      images_[t][m->header.stamp] = m;
    }));
  subs.push_back(nh.subscribe<viper::ObjectArray>(kObjects, 100, [this](const viper::ObjectArray::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    objects_[m->header.stamp] = m;
  }));
  auto connected = [&] {
    for (const char* t : {"/capture/draws", "/capture/draw_ids"})
      if (pubs[t].getNumSubscribers() < 1) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    return true;
  };
  ASSERT_TRUE(viper::test::waitFor(connected, deadline)) << "the nodes did not connect";

  const auto by_stamp = viper::test::messagesByStamp(view, pubs, false);
  for (const auto& [stamp, messages] : by_stamp) {
    for (const auto& [topic, shape] : messages) pubs[topic].publish(shape);
    EXPECT_TRUE(viper::test::waitFor([&] { return has(stamp); }, deadline)) << "no amodal objects or overlay at " << stamp;
  }
  ASSERT_GE(by_stamp.size(), 10u);

  std::unique_lock<std::mutex> lock(mutex_);
  size_t checked = 0, visible_total = 0, occluded_total = 0;
  std::map<int, size_t> levels;
  for (const auto& [stamp, frame] : by_stamp) {
    if (!amodal_.count(stamp) || !objects_.count(stamp) || !images_[kInstances].count(stamp) ||
        !images_[kOverlay].count(stamp))
      continue;
    const sensor_msgs::Image& ids_msg = *images_[kInstances].at(stamp);
    const sensor_msgs::Image& overlay = *images_[kOverlay].at(stamp);
    const viper::AmodalInstanceArray& amodal = *amodal_.at(stamp);
    const uint32_t w = ids_msg.width, h = ids_msg.height;
    ASSERT_EQ(ids_msg.encoding, "32SC1");
    const int32_t* ids = reinterpret_cast<const int32_t*>(ids_msg.data.data());
    EXPECT_EQ(amodal.header.frame_id, ids_msg.header.frame_id);
    ASSERT_EQ(overlay.encoding, "rgb8");
    ASSERT_EQ(overlay.width, w);
    ASSERT_EQ(overlay.height, h);
    ASSERT_EQ(overlay.data.size(), 3u * w * h);

    // Every tracked object the instances node shows has its amodal entry.
    std::map<int32_t, uint32_t> visible;
    for (size_t p = 0; p < size_t(w) * h; ++p)
      if (ids[p] > 0) ++visible[ids[p]];
    std::set<int32_t> tracks;
    for (const auto& o : objects_.at(stamp)->objects)
      if (o.track_id > 0) tracks.insert(o.track_id);
    std::vector<uint8_t> covered(size_t(w) * h, 0);
    std::set<int32_t> seen;
    for (const viper::AmodalInstance& a : amodal.objects) {
      SCOPED_TRACE("frame " + std::to_string(stamp.toSec()) + " track " + std::to_string(a.track_id));
      ASSERT_TRUE(tracks.count(a.track_id)) << "not an object of the frame";
      ASSERT_TRUE(seen.insert(a.track_id).second) << "twice";
      const sensor_msgs::RegionOfInterest& b = a.box;
      ASSERT_LE(b.x_offset + b.width, w);
      ASSERT_LE(b.y_offset + b.height, h);
      ASSERT_EQ(a.mask.encoding, "mono8");
      ASSERT_EQ(a.mask.width, b.width);
      ASSERT_EQ(a.mask.height, b.height);
      ASSERT_EQ(a.mask.step, b.width);
      ASSERT_EQ(a.mask.data.size(), size_t(b.width) * b.height);
      uint32_t mask_pixels = 0, inside = 0;
      uint32_t x_min = w, x_max = 0, y_min = h, y_max = 0;
      for (uint32_t r = 0; r < b.height; ++r)
        for (uint32_t c = 0; c < b.width; ++c) {
          const uint8_t m = a.mask.data[size_t(r) * b.width + c];
          ASSERT_TRUE(m == 0 || m == 255);
          if (!m) continue;
          ++mask_pixels;
          const uint32_t x = b.x_offset + c, y = b.y_offset + r;
          x_min = std::min(x_min, x), x_max = std::max(x_max, x), y_min = std::min(y_min, y), y_max = std::max(y_max, y);
          const size_t p = size_t(y) * w + x;
          covered[p] = 1;
          const uint8_t* px = overlay.data.data() + 3 * p;
          uint8_t rgb[3];
          viper::amodalColor(a.track_id, rgb);
          const bool stripe = (x + y) % 6 < 2, own = px[0] == rgb[0] && px[1] == rgb[1] && px[2] == rgb[2];
          if (ids[p] == a.track_id) {
            ++inside;
            // Off the stripes a visible pixel is its object's colour (on them another's hatch may lie).
            if (!stripe) ASSERT_TRUE(own) << "visible pixel " << x << "," << y << " not in its colour";
          } else if (stripe) {
            // An occluded pixel on a stripe is hatched: some object's colour, never black.
            ASSERT_TRUE(px[0] || px[1] || px[2]) << "occluded pixel " << x << "," << y << " not hatched";
          } else if (ids[p] <= 0) {
            ASSERT_TRUE(!px[0] && !px[1] && !px[2]) << "occluded pixel " << x << "," << y << " between stripes filled";
          }
        }
      ASSERT_EQ(mask_pixels, a.amodal_pixels);
      if (mask_pixels > 0) {  // the box is the mask's tight box
        EXPECT_EQ(x_min, b.x_offset);
        EXPECT_EQ(y_min, b.y_offset);
        EXPECT_EQ(x_max + 1, b.x_offset + b.width);
        EXPECT_EQ(y_max + 1, b.y_offset + b.height);
      }
      const uint32_t shown = visible.count(a.track_id) ? visible.at(a.track_id) : 0;
      EXPECT_EQ(inside, shown) << (shown - inside) << " visible pixels outside the amodal mask";
      EXPECT_EQ(a.visible_pixels, shown);
      ASSERT_GE(a.visible_fraction, 0.f);
      ASSERT_LE(a.visible_fraction, 1.f);
      ASSERT_GE(a.truncation, 0.f);
      ASSERT_LE(a.truncation, 1.f);
      EXPECT_NEAR(a.visible_fraction, a.amodal_pixels ? double(a.visible_pixels) / a.amodal_pixels : 0.0, 1e-6);
      const int occlusion = expectedOcclusion(a.visible_pixels, a.amodal_pixels);
      EXPECT_EQ(a.occlusion, occlusion);
      bool near_threshold = false;
      for (double t : {0.15, 0.30, 0.50}) near_threshold |= std::abs(a.truncation - t) < 1e-6;
      if (!near_threshold) EXPECT_EQ(a.difficulty, expectedDifficulty(b.height, a.occlusion, a.truncation));
      ++checked;
      visible_total += a.visible_pixels;
      occluded_total += a.amodal_pixels - a.visible_pixels;
      ++levels[a.occlusion];
    }
    for (const auto& [track, n] : visible)
      EXPECT_TRUE(seen.count(track)) << "frame " << stamp << ": track " << track << " (" << n
                                     << " visible px) has no amodal entry";
    for (size_t p = 0; p < size_t(w) * h; ++p)
      if (!covered[p]) {
        const uint8_t* px = overlay.data.data() + 3 * p;
        ASSERT_TRUE(px[0] == 0 && px[1] == 0 && px[2] == 0) << "overlay drawn outside every mask at pixel " << p;
      }
  }
  EXPECT_GE(amodal_.size(), by_stamp.size());
  EXPECT_GT(checked, 20u);
  EXPECT_GT(visible_total, 1000u);
  std::cout << "amodal_tester: " << amodal_.size() << " frames, " << checked << " objects, " << visible_total
            << " visible px all inside their masks, " << occluded_total << " occluded px; occlusion levels";
  for (const auto& [level, n] : levels) std::cout << " " << level << ":" << n;
  std::cout << std::endl;

  // Nobody listens any more: the amodal node lets its inputs go.
  lock.unlock();  // the callbacks take it: a subscriber's shutdown waits for them
  subs.clear();
  EXPECT_TRUE(viper::test::waitFor([] { return subscribersOf(kInstances).empty(); }, deadline))
      << "amodal still reads instance_ids without subscribers";
}

}  // namespace

int main(int argc, char** argv) { return viper::test::runTester(argc, argv, "amodal_tester"); }
