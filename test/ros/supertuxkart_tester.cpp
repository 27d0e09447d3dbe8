// SuperTuxKart live through every ground-truth node (launch/supertuxkart_live.launch, run by
// test/ros/supertuxkart_live.test): the game races under capture, the bridge follows the capture,
// and the nodes label it with the shipped Candela City table. Checks what comes out: every frame
// gets a semantic image whose drawn pixels all have a class, the followed kart keeps one instance
// id, its box is a car, and forward flow covers the scene.
// Private parameters: frames (frames the game captures), timeout_s (240).
#include "tester_main.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <set>

namespace {

struct Collected {
  std::mutex mutex;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> draw_ids, semantic, instances;
  size_t flow_frames = 0, flow_finite = 0, flow_pixels = 0;
  size_t frames_with_car_box = 0;
};

TEST(SuperTuxKartLive, EveryNodeLabelsAndTracksTheGame) {
  ros::NodeHandle nh, pnh("~");
  int frames = 30;
  double timeout_s = 240;
  pnh.param("frames", frames, 30);
  pnh.param("timeout_s", timeout_s, 240.0);
  Collected c;
  auto keep = [&c](std::map<ros::Time, sensor_msgs::ImageConstPtr>& into) {
    return [&c, &into](const sensor_msgs::ImageConstPtr& m) {
      std::lock_guard<std::mutex> lock(c.mutex);
      into[m->header.stamp] = m;
    };
  };
  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe<sensor_msgs::Image>("/capture/draw_ids", 100, keep(c.draw_ids)));
  subs.push_back(nh.subscribe<sensor_msgs::Image>("/ground_truth/semantic", 100, keep(c.semantic)));
  subs.push_back(nh.subscribe<sensor_msgs::Image>("/ground_truth/instance_ids", 100, keep(c.instances)));
  subs.push_back(nh.subscribe<sensor_msgs::Image>("/ground_truth/flow/forward", 100, [&c](const sensor_msgs::ImageConstPtr& m) {
    const float* uv = reinterpret_cast<const float*>(m->data.data());
    size_t finite = 0;
    for (size_t i = 0; i + 1 < m->data.size() / 4; i += 2) finite += std::isfinite(uv[i]) && std::isfinite(uv[i + 1]);
    std::lock_guard<std::mutex> lock(c.mutex);
    ++c.flow_frames;
    c.flow_finite += finite;
    c.flow_pixels += m->data.size() / 8;
  }));
  subs.push_back(nh.subscribe<viper::Box3DArray>("/ground_truth/boxes", 100, [&c](const viper::Box3DArrayConstPtr& m) {
    bool car = false;
    for (const auto& b : m->boxes) car |= b.class_id == 24;
    std::lock_guard<std::mutex> lock(c.mutex);
    c.frames_with_car_box += car;
  }));

  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(c.mutex);
      if (static_cast<int>(c.semantic.size()) >= frames && static_cast<int>(c.flow_frames) >= frames - 1) break;
    }
    ros::WallDuration(0.2).sleep();
  }
  std::lock_guard<std::mutex> lock(c.mutex);
  ASSERT_GE(static_cast<int>(c.semantic.size()), frames) << "semantic images of the race's frames";
  EXPECT_GE(static_cast<int>(c.flow_frames), frames - 1);

  // Every drawn pixel has a class (the label table covers the game), frame by frame.
  size_t drawn = 0, labelled = 0;
  std::map<int32_t, size_t> frames_of_id;
  for (const auto& [stamp, sem] : c.semantic) {
    auto ids = c.draw_ids.find(stamp);
    ASSERT_NE(ids, c.draw_ids.end()) << "draw ids of the semantic image's stamp";
    const int32_t* d = reinterpret_cast<const int32_t*>(ids->second->data.data());
    for (size_t i = 0; i < sem->data.size(); ++i)
      if (d[i] != 0) ++drawn, labelled += sem->data[i] != 0;
    auto inst = c.instances.find(stamp);
    if (inst == c.instances.end()) continue;
    std::set<int32_t> seen;
    const int32_t* t = reinterpret_cast<const int32_t*>(inst->second->data.data());
    for (size_t i = 0; i < inst->second->data.size() / 4; ++i)
      if (t[i] > 0) seen.insert(t[i]);
    for (int32_t id : seen) ++frames_of_id[id];
  }
  size_t longest = 0;
  for (const auto& [id, n] : frames_of_id) longest = std::max(longest, n);
  std::printf("SuperTuxKart live: %zu frames; %.2f%% of drawn pixels labelled; longest instance id in %zu frames; "
              "forward flow on %.1f%% of pixels; %zu frames with a car box\n",
              c.semantic.size(), 100.0 * labelled / std::max<size_t>(drawn, 1), longest,
              100.0 * c.flow_finite / std::max<size_t>(c.flow_pixels, 1), c.frames_with_car_box);
  EXPECT_GE(labelled, 0.99 * drawn);
  EXPECT_GE(longest, c.instances.size() - 1) << "the followed kart keeps its instance id";
  EXPECT_GE(c.flow_finite, c.flow_pixels / 2) << "flow on the scene (the sky has none)";
  EXPECT_GE(c.frames_with_car_box + 1, c.semantic.size()) << "the followed kart's box in every frame";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "supertuxkart_tester", 2);
}
