// Replays a raw bag into replay.launch's nodelets plus baselines.launch frame by frame and scores the
// baselines against the ground truth computed by the package itself: every frame pair gets a
// baseline flow with the earlier frame's stamp, the image's size and 32FC2; its average endpoint
// error (on pixels where the ground-truth forward flow is finite and visible) is finite and
// bounded relative to that of zero flow; the VO publishes an odometry for every frame, in `map`, and it
// moves at all and its trajectory stays within a bounded drift of the ground-truth odometry. Prints all figures.
// Bounds measured on bags/test_scene_raw.bag (docs/baselines.md has the numbers): that scene is
// flat-shaded and rainy, and the dense flow baselines do worse there than zero flow, so the flow
// bound is only a regression guard; the VO bound (0.75 of the path) is one a camera standing still
// (1.0) fails.
// Private parameters: bag (path, required), timeout_s (120), max_epe_ratio (flow EPE over all
// scored pixels / zero-flow EPE, 3.0), min_gradient (gray step of a "textured" pixel, 20; printed
// only), max_drift (end and max translation error / ground-truth path length, 0.75),
// max_rotation_deg (final rotation error, 5).
#include "tester_main.h"
#include "bag_publishers.h"

#include "viper/ros/conversions/pose_conversions.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

namespace {

const std::string kImage = "/capture/color/image_raw", kGtFlow = "/ground_truth/flow/forward",
                  kGtVis = "/ground_truth/flow/forward_visible", kFlow = "/baselines/flow",
                  kGtOdom = "/ground_truth/odom", kVo = "/baselines/odom";

class Baselines : public ::testing::Test {
 protected:
  std::mutex mutex_;
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> images_;
  std::map<std::string, std::map<ros::Time, nav_msgs::Odometry::ConstPtr>> odom_;
  std::map<ros::Time, bool> objects_;

  template <typename M>
  bool has(const std::map<std::string, std::map<ros::Time, M>>& m, const std::string& topic, const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = m.find(topic);
    return it != m.end() && it->second.count(t) > 0;
  }
  bool hasObjects(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return objects_.count(t) > 0;
  }
};

TEST_F(Baselines, ScoredAgainstGroundTruth) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  const double timeout_s = pnh.param("timeout_s", 120.0);
  const double max_epe_ratio = pnh.param("max_epe_ratio", 3.0);
  const double min_gradient = pnh.param("min_gradient", 20.0);
  const double max_drift = pnh.param("max_drift", 0.75);
  const double max_rotation_deg = pnh.param("max_rotation_deg", 5.0);

  std::vector<ros::Subscriber> subs;
  for (const std::string& t : {kGtFlow, kGtVis, kFlow})
    subs.push_back(nh.subscribe<sensor_msgs::Image>(t, 100, [this, t](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      images_[t][m->header.stamp] = m;
    }));
  for (const std::string& t : {kGtOdom, kVo})
    subs.push_back(nh.subscribe<nav_msgs::Odometry>(t, 100, [this, t](const nav_msgs::Odometry::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      odom_[t][m->header.stamp] = m;
    }));
  subs.push_back(nh.subscribe<viper::ObjectArray>("/ground_truth/objects", 100, [this](const viper::ObjectArrayConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    objects_[m->header.stamp] = true;
  }));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, ros::Publisher> pubs = viper::test::advertiseBagTopics(nh, view);
  for (const std::string& t : {kImage, std::string("/capture/color/camera_info"), std::string("/capture/draws")})
    ASSERT_TRUE(pubs.count(t)) << bag_path << " has no " << t;

  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  auto missing = [&]() -> std::string {
    // Nodelets of one manager share one connection per topic: count processes, not nodelets.
    if (pubs[kImage].getNumSubscribers() < 1) return kImage + " has no subscriber";
    if (pubs["/capture/color/camera_info"].getNumSubscribers() < 1) return "camera_info has no subscriber";
    if (pubs["/capture/draws"].getNumSubscribers() < 1) return "draws has no subscriber";
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return s.getTopic() + " has no publisher";
    return "";
  };
  while (!missing().empty() && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  ASSERT_EQ(missing(), "") << "ground-truth and baseline nodelets did not connect within " << timeout_s << " s";
  // Each node subscribes its inputs right after advertising its outputs: let that finish.
  ros::WallDuration(1.0).sleep();

  std::map<ros::Time, std::vector<float>> gray;  // the bag's images, for the textured-pixel mask
  // Group the bag's messages by header stamp; camera_info goes first so the VO has K for the image.
  auto keep_gray = [&](const rosbag::MessageInstance& m, const ros::Time& stamp) {
    auto img = m.instantiate<sensor_msgs::Image>();
    if (!img || m.getTopic() != kImage || img->encoding != "rgb8") return;
    std::vector<float>& g = gray[stamp];
    g.resize(static_cast<size_t>(img->width) * img->height);
    for (size_t p = 0; p < g.size(); ++p) g[p] = (img->data[3 * p] + img->data[3 * p + 1] + img->data[3 * p + 2]) / 3.0f;
  };
  const auto by_stamp = viper::test::messagesByStamp(view, pubs, /*camera_info_first=*/true, keep_gray);
  std::vector<ros::Time> frames;
  auto done = [&](size_t i) {  // frame i is through every node that can finish it before frame i+1
    const ros::Time t = frames[i];
    return hasObjects(t) && has(odom_, kGtOdom, t) && has(odom_, kVo, t) &&
           (i == 0 || (has(images_, kGtFlow, frames[i - 1]) && has(images_, kGtVis, frames[i - 1]) &&
                       has(images_, kFlow, frames[i - 1])));
  };
  for (const auto& [stamp, messages] : by_stamp) {
    if (!frames.empty())
      while (!done(frames.size() - 1) && ros::WallTime::now() < deadline) ros::WallDuration(0.005).sleep();
    frames.push_back(stamp);
    for (const auto& [topic, shape] : messages) pubs[topic].publish(shape);
  }
  const size_t n = frames.size();
  ASSERT_GE(n, 3u);
  while (!done(n - 1) && ros::WallTime::now() < deadline) ros::WallDuration(0.01).sleep();
  ros::WallDuration(0.2).sleep();  // anything published late or twice would show up now

  std::lock_guard<std::mutex> lock(mutex_);
  // Flow: one per frame pair, with the earlier frame's stamp, the image's size, 32FC2.
  std::vector<ros::Time> flow_stamps;
  for (const auto& [stamp, img] : images_[kFlow]) flow_stamps.push_back(stamp);
  EXPECT_EQ(flow_stamps, std::vector<ros::Time>(frames.begin(), frames.end() - 1));
  double sum_epe = 0, sum_zero = 0, tex_epe = 0, tex_zero = 0;
  size_t pixels = 0, tex_pixels = 0;
  for (size_t i = 0; i + 1 < n; ++i) {
    const auto f = images_[kFlow].find(frames[i]);
    const auto g = images_[kGtFlow].find(frames[i]);
    const auto v = images_[kGtVis].find(frames[i]);
    if (f == images_[kFlow].end() || g == images_[kGtFlow].end() || v == images_[kGtVis].end()) {
      ADD_FAILURE() << "frame " << i << ": flow missing";
      continue;
    }
    const sensor_msgs::Image& flow = *f->second;
    const sensor_msgs::Image& gt = *g->second;
    ASSERT_EQ(flow.encoding, "32FC2");
    ASSERT_EQ(flow.width, gt.width);
    ASSERT_EQ(flow.height, gt.height);
    ASSERT_EQ(flow.step, flow.width * 8);
    ASSERT_EQ(flow.data.size(), static_cast<size_t>(flow.step) * flow.height);
    ASSERT_EQ(gt.step, gt.width * 8);
    const float* b = reinterpret_cast<const float*>(flow.data.data());
    const float* u = reinterpret_cast<const float*>(gt.data.data());
    const uint8_t* vis = v->second->data.data();
    double frame_epe = 0, frame_zero = 0;
    size_t frame_pixels = 0;
    const std::vector<float>& img = gray[frames[i]];
    ASSERT_EQ(img.size(), static_cast<size_t>(gt.width) * gt.height) << "frame " << i << ": no rgb8 image in the bag";
    for (size_t p = 0; p < static_cast<size_t>(gt.width) * gt.height; ++p) {
      if (vis[p] != 255 || !std::isfinite(u[2 * p]) || !std::isfinite(u[2 * p + 1])) continue;
      frame_epe += std::hypot(b[2 * p] - u[2 * p], b[2 * p + 1] - u[2 * p + 1]);
      frame_zero += std::hypot(u[2 * p], u[2 * p + 1]);
      ++frame_pixels;
      // Textured: a gray-level step of more than min_gradient between the pixel's neighbours.
      const size_t x = p % gt.width, y = p / gt.width;
      if (x == 0 || y == 0 || x + 1 == gt.width || y + 1 == gt.height) continue;
      const double gx = img[p + 1] - img[p - 1], gy = img[p + gt.width] - img[p - gt.width];
      if (std::hypot(gx, gy) < min_gradient) continue;
      tex_epe += std::hypot(b[2 * p] - u[2 * p], b[2 * p + 1] - u[2 * p + 1]);
      tex_zero += std::hypot(u[2 * p], u[2 * p + 1]);
      ++tex_pixels;
    }
    std::printf("flow %2zu -> %2zu: EPE %.3f px, zero-flow EPE %.3f px over %zu pixels\n", i, i + 1,
                frame_pixels ? frame_epe / frame_pixels : NAN, frame_pixels ? frame_zero / frame_pixels : NAN,
                frame_pixels);
    sum_epe += frame_epe, sum_zero += frame_zero, pixels += frame_pixels;
  }
  ASSERT_GT(pixels, 0u) << "no finite visible ground-truth flow";
  const double epe = sum_epe / pixels, zero_epe = sum_zero / pixels;
  std::printf("flow_baseline: average EPE %.3f px, zero flow %.3f px (%zu pixels, %zu pairs)\n", epe, zero_epe,
              pixels, n - 1);
  ASSERT_GT(tex_pixels, 0u) << "no textured pixels with ground-truth flow";
  std::printf("flow_baseline: textured pixels (gradient >= %.0f): EPE %.3f px, zero flow %.3f px (%zu pixels)\n",
              min_gradient, tex_epe / tex_pixels, tex_zero / tex_pixels, tex_pixels);
  EXPECT_TRUE(std::isfinite(epe));
  EXPECT_LT(epe, max_epe_ratio * zero_epe);

  // VO: one odometry per frame (the first is the start pose), in map, scored against ground truth.
  std::vector<ros::Time> vo_stamps;
  for (const auto& [stamp, m] : odom_[kVo]) {
    vo_stamps.push_back(stamp);
    EXPECT_EQ(m->header.frame_id, "map");
    EXPECT_FALSE(m->child_frame_id.empty());
  }
  EXPECT_EQ(vo_stamps, frames);
  double path = 0, max_err = 0, vo_path = 0;
  Eigen::Isometry3d last_gt = Eigen::Isometry3d::Identity(), last_vo = last_gt;
  for (size_t i = 0; i < n; ++i) {
    const auto g = odom_[kGtOdom].find(frames[i]);
    const auto v = odom_[kVo].find(frames[i]);
    ASSERT_TRUE(g != odom_[kGtOdom].end() && v != odom_[kVo].end()) << "frame " << i << ": odometry missing";
    const Eigen::Isometry3d pg = viper::fromPoseMsg(g->second->pose.pose);
    const Eigen::Isometry3d pv = viper::fromPoseMsg(v->second->pose.pose);
    if (i > 0) path += (pg.translation() - last_gt.translation()).norm();
    if (i > 0) vo_path += (pv.translation() - last_vo.translation()).norm();
    const double err = (pv.translation() - pg.translation()).norm();
    max_err = std::max(max_err, err);
    std::printf("vo %2zu: position error %.4f m, path so far %.4f m\n", i, err, path);
    last_gt = pg, last_vo = pv;
  }
  const double end_err = (last_vo.translation() - last_gt.translation()).norm();
  const double rot_deg = Eigen::AngleAxisd((last_gt.linear().transpose() * last_vo.linear())).angle() * 180 / M_PI;
  std::printf("vo_baseline: path %.3f m, end translation error %.4f m (%.2f %%), max %.4f m, end rotation "
              "error %.3f deg\n", path, end_err, path > 0 ? 100 * end_err / path : NAN, max_err, rot_deg);
  ASSERT_GT(path, 0) << "ground truth does not move: nothing to score";
  EXPECT_GT(vo_path, 0) << "the VO never tracked a single step";
  EXPECT_LT(end_err / path, max_drift);
  EXPECT_LT(max_err / path, max_drift);
  EXPECT_LT(rot_deg, max_rotation_deg);
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "baselines_tester");
}
