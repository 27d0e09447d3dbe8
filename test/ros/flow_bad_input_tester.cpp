// Sends the flow node broken frames between good ones and checks, for each kind of breakage, that
// the node logs an error naming the topic and the problem (seen on /rosout), that exactly the
// affected pixels lose their flow (or the frame is dropped and no flow spans it), and that the node
// keeps running. Cases: no object list for a frame, a visible draw missing from the object list,
// a deformed draw without vertex positions, NaN depth, images whose sizes disagree, a stamp older
// than the previous frame.
// The scene: 8x4 pixels, columns 0-1 a static road (draw 0), 2-3 a car moving along x (draw 1,
// track 7), 4-5 a person (draw 2, track 8: one deformed triangle), 6-7 sky; every surface 10 m away.
#include "tester_draws.h"
#include "tester_main.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>
#include <viper/DrawList.h>
#include <viper/MeshStore.h>
#include <viper/ObjectArray.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

namespace {

constexpr uint32_t kW = 8, kH = 4;
enum Column : uint32_t { kRoad = 0, kCar = 2, kPerson = 4, kSky = 6 };

struct Frame {
  viper::DrawList draws;
  sensor_msgs::Image depth, draw_ids, primitive_ids;
  viper::ObjectArray objects;
};

viper::Draw draw(uint32_t index, uint64_t mesh, float x) { return viper::test::draw(index, mesh, x, 8); }

sensor_msgs::Image image(const std_msgs::Header& header, const std::string& encoding, const void* data,
                         uint32_t w = kW, uint32_t h = kH) {
  sensor_msgs::Image m;
  m.header = header;
  m.width = w, m.height = h, m.encoding = encoding, m.step = 4 * w;
  m.data.resize(static_cast<size_t>(m.step) * h);
  std::memcpy(m.data.data(), data, m.data.size());
  return m;
}

// A consistent frame at time t with capture frame number `number`.
Frame goodFrame(double t, uint64_t number) {
  Frame f;
  f.draws.header.stamp = ros::Time(t);
  f.draws.header.frame_id = "camera_optical";
  f.draws.frame_number = number;
  f.draws.draws = {draw(0, 2, 0.0f), draw(1, 1, 0.1f * number), draw(2, 3, 0.0f)};
  // The person: one triangle covering the view at 10 m, sliding right a little every frame.
  const float dx = 0.2f * number;
  f.draws.draws[2].deformed_clip_xyzw = {-10 + dx, -10, 9.8f, 10, 30 + dx, -10, 9.8f, 10, -10 + dx, 30, 9.8f, 10};
  int32_t ids[kW * kH], prims[kW * kH];
  float depth[kW * kH];
  for (uint32_t p = 0; p < kW * kH; ++p) {
    const uint32_t x = p % kW;
    ids[p] = x < kSky ? static_cast<int32_t>(x / 2 + 1) : 0;
    prims[p] = x < kSky ? 0 : -1;
    depth[p] = x < kSky ? 10.0f : std::nanf("");
  }
  f.depth = image(f.draws.header, "32FC1", depth);
  f.draw_ids = image(f.draws.header, "32SC1", ids);
  f.primitive_ids = image(f.draws.header, "32SC1", prims);
  f.objects.header = f.draws.header;
  f.objects.objects.resize(3);
  for (uint32_t i = 0; i < 3; ++i) {
    f.objects.objects[i].draws = {i};
    f.objects.objects[i].track_id = i == 0 ? 0 : static_cast<int32_t>(6 + i);
  }
  return f;
}

class FlowBadInput : public ::testing::Test {
 protected:
  ros::NodeHandle nh_;
  std::mutex mutex_;
  std::map<std::string, std::map<double, sensor_msgs::Image::ConstPtr>> out_;  // topic -> stamp -> image
  std::vector<rosgraph_msgs::Log> errors_;
  ros::Publisher draws_pub_, depth_pub_, ids_pub_, prims_pub_, objects_pub_, mesh_pub_;
  std::vector<ros::Subscriber> subs_;
  double t_ = 100.0;
  uint64_t number_ = 0;

  const std::string kFwd = "/ground_truth/flow/forward", kBwd = "/ground_truth/flow/backward";

  void send(const Frame& f, bool with_objects = true) {
    draws_pub_.publish(f.draws);
    depth_pub_.publish(f.depth);
    ids_pub_.publish(f.draw_ids);
    prims_pub_.publish(f.primitive_ids);
    if (with_objects) objects_pub_.publish(f.objects);
  }
  Frame next() {
    t_ += 1.0;
    return goodFrame(t_, ++number_);
  }
  sensor_msgs::Image::ConstPtr get(const std::string& topic, double t) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = out_[topic].find(t);
    return it == out_[topic].end() ? nullptr : it->second;
  }
  template <typename Pred>
  bool waitUntil(Pred pred, double timeout_s = 20) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < deadline) {
      if (pred()) return true;
      ros::WallDuration(0.01).sleep();
    }
    return pred();
  }
  sensor_msgs::Image::ConstPtr waitFor(const std::string& topic, double t) {
    waitUntil([&] { return get(topic, t) != nullptr; });
    return get(topic, t);
  }
  // Two good frames: the second one's backward flow and the first one's forward flow come out.
  void expectAlive(const std::string& after) {
    const Frame a = next(), b = next();
    send(a);
    send(b);
    EXPECT_TRUE(waitFor(kBwd, t_)) << "no backward flow after " << after;
    EXPECT_TRUE(waitFor(kFwd, t_ - 1.0)) << "no forward flow after " << after;
  }
  // An error from the flow node on /rosout whose text holds both `topic` and `problem`.
  bool errorLogged(const std::string& topic, const std::string& problem) {
    return waitUntil([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& e : errors_)
        if (e.msg.find(topic) != std::string::npos && e.msg.find(problem) != std::string::npos) return true;
      return false;
    }, 10);
  }
  // Whether the flow image has finite flow exactly in columns [x0, x1) (among the surface columns).
  static std::string finiteColumns(const sensor_msgs::Image& flow) {
    std::string s;
    const float* uv = reinterpret_cast<const float*>(flow.data.data());
    for (uint32_t y = 0; y < kH; ++y) {
      for (uint32_t x = 0; x < kW; ++x) s += std::isfinite(uv[2 * (y * kW + x)]) ? 'F' : '.';
      s += y + 1 < kH ? "|" : "";
    }
    return s;
  }
  static std::string rows(const std::string& row) {
    std::string s;
    for (uint32_t y = 0; y < kH; ++y) s += row + (y + 1 < kH ? "|" : "");
    return s;
  }
};

TEST_F(FlowBadInput, BrokenInputLosesOnlyItsPixelsAndTheNodeKeepsRunning) {
  for (const std::string& t : {kFwd, kBwd}) {
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>(t, 50, [this, t](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      out_[t][m->header.stamp.toSec()] = m;
    }));
  }
  subs_.push_back(nh_.subscribe<rosgraph_msgs::Log>("/rosout", 100, [this](const rosgraph_msgs::Log::ConstPtr& m) {
    if (m->level < rosgraph_msgs::Log::ERROR || m->name != "/ground_truth/flow") return;
    std::lock_guard<std::mutex> lock(mutex_);
    errors_.push_back(*m);
  }));
  draws_pub_ = nh_.advertise<viper::DrawList>("/capture/draws", 20);
  depth_pub_ = nh_.advertise<sensor_msgs::Image>("/capture/depth/image_raw", 20);
  ids_pub_ = nh_.advertise<sensor_msgs::Image>("/capture/draw_ids", 20);
  prims_pub_ = nh_.advertise<sensor_msgs::Image>("/capture/primitive_ids", 20);
  objects_pub_ = nh_.advertise<viper::ObjectArray>("/ground_truth/objects", 20);
  mesh_pub_ = nh_.advertise<viper::MeshStore>("/capture/mesh_store", 1, true);
  viper::MeshStore store;
  store.meshes.resize(1);
  store.meshes[0].key = 3;
  store.meshes[0].positions_xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  store.meshes[0].indices = {0, 1, 2};
  mesh_pub_.publish(store);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(waitUntil([&] {
    for (const auto* p : {&draws_pub_, &depth_pub_, &ids_pub_, &prims_pub_, &objects_pub_, &mesh_pub_})
      if (p->getNumSubscribers() < 1) return false;
    for (const auto& s : subs_)
      if (s.getNumPublishers() < 1) return false;
    return true;
  }, 30)) << "flow node did not come up";

  // Connections may settle a moment after they appear: send good frames until flow comes out.
  bool warm = false;
  for (int i = 0; i < 50 && !warm; ++i) {
    send(next());
    warm = waitUntil([&] { return get(kBwd, t_) != nullptr; }, 0.5);
  }
  ASSERT_TRUE(warm) << "no flow came out of the node";
  expectAlive("start");
  const std::string all = rows("FFFFFF.."), no_car = rows("FF..FF.."), no_person = rows("FFFF....");
  EXPECT_EQ(finiteColumns(*get(kFwd, t_ - 1.0)), all) << "a good frame: flow on every surface, none on the sky";
  EXPECT_EQ(finiteColumns(*get(kBwd, t_)), all);

  {  // no object list for a frame: dropped, no flow spans it
    const double before = t_;
    const Frame f = next();
    send(f, /*with_objects=*/false);
    expectAlive("a frame without an object list");
    EXPECT_TRUE(errorLogged("/ground_truth/objects", "no object list")) << "no error naming the objects topic";
    EXPECT_FALSE(get(kBwd, f.draws.header.stamp.toSec())) << "backward flow of a frame without objects";
    EXPECT_FALSE(get(kFwd, before)) << "forward flow across a frame without objects";
    EXPECT_FALSE(get(kFwd, f.draws.header.stamp.toSec()));
  }
  {  // the car is in no object: its pixels have no association, the rest keeps its flow
    Frame f = next();
    f.objects.objects.erase(f.objects.objects.begin() + 1);
    send(f);
    const auto fwd = waitFor(kFwd, t_ - 1.0), bwd = waitFor(kBwd, t_);
    ASSERT_TRUE(fwd && bwd) << "a frame with an incomplete object list was dropped";
    EXPECT_EQ(finiteColumns(*fwd), no_car) << "forward flow into a frame whose car is in no object";
    EXPECT_EQ(finiteColumns(*bwd), no_car) << "backward flow of a frame whose car is in no object";
    EXPECT_TRUE(errorLogged("/ground_truth/objects", "in no object")) << "no error naming the objects topic";
    expectAlive("a draw missing from the object list");
  }
  {  // the deformed person without vertex positions: its pixels have no flow
    Frame f = next();
    f.draws.draws[2].deformed_clip_xyzw.clear();
    send(f);
    const auto fwd = waitFor(kFwd, t_ - 1.0), bwd = waitFor(kBwd, t_);
    ASSERT_TRUE(fwd && bwd) << "a frame with a deformed draw without positions was dropped";
    EXPECT_EQ(finiteColumns(*fwd), no_person);
    EXPECT_EQ(finiteColumns(*bwd), no_person);
    EXPECT_TRUE(errorLogged("/capture/draws", "missing vertex positions")) << "no error naming the draws topic";
    expectAlive("a deformed draw without vertex positions");
  }
  {  // a draw id past the frame's three draws: dropped, no flow spans it
    const double before = t_;
    Frame f = next();
    int32_t* ids = reinterpret_cast<int32_t*>(f.draw_ids.data.data());
    ids[kW + 1] = 9;
    send(f);
    expectAlive("a draw id past the draws");
    EXPECT_TRUE(errorLogged("/capture/draws", "draw id 9 at pixel " + std::to_string(kW + 1) + " in draw_ids, but only 3"))
        << "no error naming the draw id and its pixel";
    EXPECT_FALSE(get(kBwd, f.draws.header.stamp.toSec())) << "backward flow of a frame with a draw id past its draws";
    EXPECT_FALSE(get(kFwd, before)) << "forward flow into a frame with a draw id past its draws";
    EXPECT_FALSE(get(kFwd, f.draws.header.stamp.toSec()));
  }
  {  // NaN depth on three pixels: those pixels have no flow out of this frame
    Frame f = next();
    float* depth = reinterpret_cast<float*>(f.depth.data.data());
    depth[0 * kW + 0] = depth[0 * kW + 2] = depth[1 * kW + 3] = std::nanf("");
    send(f);
    const auto fwd = waitFor(kFwd, t_ - 1.0), bwd = waitFor(kBwd, t_);
    ASSERT_TRUE(fwd && bwd) << "a frame with NaN depth was dropped";
    EXPECT_EQ(finiteColumns(*fwd), all) << "flow into NaN depth is still defined (nothing in front)";
    std::string holes = all;
    holes[0] = holes[2] = holes[kW + 1 + 3] = '.';
    EXPECT_EQ(finiteColumns(*bwd), holes) << "pixels with NaN depth must have no flow";
    EXPECT_TRUE(errorLogged("/capture/depth/image_raw", "no finite positive depth")) << "no error naming depth";
    const Frame g = next();
    send(g);
    const auto fwd2 = waitFor(kFwd, t_ - 1.0);
    ASSERT_TRUE(fwd2);
    EXPECT_EQ(finiteColumns(*fwd2), holes);
    expectAlive("NaN depth");
  }
  {  // images whose sizes disagree: dropped, no flow spans the frame
    const double before = t_;
    Frame f = next();
    const float depth[4] = {10, 10, 10, 10};
    f.depth = image(f.draws.header, "32FC1", depth, 2, 2);
    send(f);
    expectAlive("a depth image of the wrong size");
    EXPECT_TRUE(errorLogged("/capture/depth/image_raw", "sizes disagree")) << "no error naming depth";
    EXPECT_FALSE(get(kBwd, f.draws.header.stamp.toSec())) << "backward flow of a frame with a wrong-size depth image";
    EXPECT_FALSE(get(kFwd, before)) << "forward flow across a dropped frame";

    const double before2 = t_;
    Frame g = next();
    g.primitive_ids.data.resize(g.primitive_ids.data.size() - 4);
    send(g);
    expectAlive("a truncated primitive id image");
    EXPECT_TRUE(errorLogged("/capture/primitive_ids", "sizes disagree")) << "no error naming primitive ids";
    EXPECT_FALSE(get(kBwd, g.draws.header.stamp.toSec()));
    EXPECT_FALSE(get(kFwd, before2));
  }
  {  // a stamp from the past (a stale frame sent again): dropped, the sequence goes on
    const double last = t_;
    Frame old = goodFrame(t_ - 0.5, number_);
    send(old);
    const Frame f = next();
    send(f);
    EXPECT_TRUE(waitFor(kBwd, t_)) << "no backward flow after a frame from the past";
    EXPECT_TRUE(waitFor(kFwd, last)) << "a frame from the past broke the sequence";
    EXPECT_FALSE(get(kBwd, last - 0.5)) << "flow for a frame from the past";
    EXPECT_TRUE(errorLogged("/capture/draws", "is not after")) << "no error naming the draws topic";
    expectAlive("a frame from the past");
  }
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "flow_bad_input_tester");
}
