// Replays a raw bag into replay.launch's nodelets (instances + flow) frame by frame and checks the
// flow node's output: every frame pair gets forward and backward flow with the right stamps, sizes
// and encodings; most surface pixels have flow; forward then backward flow returns to the start
// pixel; static surfaces move exactly as the camera's ego-motion predicts (from depth and the
// camera matrices, computed here independently) and moving objects do not; wide-baseline flow
// agrees with two composed single steps; the correspondences service answers with the topics' flow
// and the relative pose that the odometry node's poses give.
// Private parameters: bag (path, required), wide_baseline (k of the flow node, 2), timeout_s (120).
#include "tester_main.h"
#include "bag_publishers.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/capture/capture_frame.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ground_truth/scene_flow.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <topic_tools/shape_shifter.h>
#include <viper/Correspondences.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

namespace {

// One image as floats (flow: 2 per pixel) or bytes (mask).
struct Received {
  sensor_msgs::Image::ConstPtr msg;
  const float* uv() const { return reinterpret_cast<const float*>(msg->data.data()); }
  const uint8_t* mask() const { return msg->data.data(); }
};

// What the bag says about one frame.
struct BagFrame {
  viper::CaptureFrame frame;  // draws, draw ids
  std::vector<float> depth_m;
};

struct Percentiles {
  size_t n = 0;
  double median = NAN, p90 = NAN, p99 = NAN;
};
Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  p.n = v.size();
  if (v.empty()) return p;
  auto at = [&](double q) {
    const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
    std::nth_element(v.begin(), v.begin() + i, v.end());
    return v[i];
  };
  p.median = at(0.5), p.p90 = at(0.9), p.p99 = at(0.99);
  return p;
}
std::string describe(const Percentiles& p) {
  std::ostringstream s;
  s << "n=" << p.n << " median=" << p.median << " p90=" << p.p90 << " p99=" << p.p99 << " px";
  return s.str();
}

// Bilinear sample of flow `uv` at (x, y) of a w x h frame whose draw ids are `ids`: only where the
// four neighbours show the same draw, have flow and are marked visible by `mask`.
std::optional<Eigen::Vector2d> sampleSameSurface(const float* uv, const uint8_t* mask, const std::vector<uint32_t>& ids,
                                                 int w, int h, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= w || y0 + 1 >= h) return std::nullopt;
  const size_t p[4] = {static_cast<size_t>(y0) * w + x0, static_cast<size_t>(y0) * w + x0 + 1,
                       static_cast<size_t>(y0 + 1) * w + x0, static_cast<size_t>(y0 + 1) * w + x0 + 1};
  for (size_t q : p) {
    if (ids[q] == 0 || ids[q] != ids[p[0]] || mask[q] != 255 || !std::isfinite(uv[2 * q])) return std::nullopt;
  }
  const double fx = x - x0, fy = y - y0;
  const double wt[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  Eigen::Vector2d out(0, 0);
  for (int i = 0; i < 4; ++i) out += wt[i] * Eigen::Vector2d(uv[2 * p[i]], uv[2 * p[i] + 1]);
  return out;
}

class FlowReplay : public ::testing::Test {
 protected:
  std::mutex mutex_;
  std::map<std::string, std::map<ros::Time, Received>> images_;  // topic -> stamp -> image
  std::map<ros::Time, viper::ObjectArray::ConstPtr> objects_;
  std::map<ros::Time, nav_msgs::Odometry::ConstPtr> odom_;
  std::map<ros::Time, BagFrame> bag_;
  std::vector<ros::Time> frames_;
  int k_ = 2;

  size_t count(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    return images_[topic].size();
  }
  bool has(const std::string& topic, const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return images_[topic].count(t) > 0;
  }
  bool hasObjects(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return objects_.count(t) > 0;
  }
  const Received& image(const std::string& topic, const ros::Time& t) { return images_[topic].at(t); }
};

const std::string kFwd = "/ground_truth/flow/forward", kFwdVis = "/ground_truth/flow/forward_visible",
                  kBwd = "/ground_truth/flow/backward", kBwdVis = "/ground_truth/flow/backward_visible",
                  kWide = "/ground_truth/flow/wide", kWideVis = "/ground_truth/flow/wide_visible",
                  kScene = "/ground_truth/flow/scene_flow";

TEST_F(FlowReplay, FlowOfEveryFramePair) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  double timeout_s = 120;
  pnh.param("timeout_s", timeout_s, 120.0);
  pnh.param("wide_baseline", k_, 2);
  ASSERT_GE(k_, 2);

  std::vector<ros::Subscriber> subs;
  for (const std::string& t : {kFwd, kFwdVis, kBwd, kBwdVis, kWide, kWideVis, kScene}) {
    subs.push_back(nh.subscribe<sensor_msgs::Image>(t, 100, [this, t](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      images_[t][m->header.stamp] = Received{m};
    }));
  }
  subs.push_back(nh.subscribe<viper::ObjectArray>("/ground_truth/objects", 100, [this](const viper::ObjectArrayConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    objects_[m->header.stamp] = m;
  }));
  subs.push_back(nh.subscribe<nav_msgs::Odometry>("/ground_truth/odom", 100, [this](const nav_msgs::OdometryConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    odom_[m->header.stamp] = m;
  }));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, ros::Publisher> pubs = viper::test::advertiseBagTopics(nh, view);
  for (const char* t : {"/capture/draws", "/capture/draw_ids", "/capture/depth/image_raw", "/capture/primitive_ids"})
    ASSERT_TRUE(pubs.count(t)) << bag_path << " has no " << t;

  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  auto connected = [&] {
    for (const char* t : {"/capture/draws", "/capture/draw_ids", "/capture/depth/image_raw", "/capture/primitive_ids"})
      if (pubs[t].getNumSubscribers() < 1) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    return ros::service::exists("/ground_truth/flow/correspondences", false);
  };
  while (!connected() && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  ASSERT_TRUE(connected()) << "instances and flow did not connect within " << timeout_s << " s";

  // The bag interleaves the messages of neighbouring frames: group them by header stamp, send the
  // mesh store first, then each frame once the previous one came out of instances and, from the
  // second frame on, out of flow as backward flow.
  auto keep_frame = [&](const rosbag::MessageInstance& m, const ros::Time& stamp) {
    if (auto draws = m.instantiate<viper::DrawList>()) {
      viper::fromDrawListMsg(*draws, bag_[stamp].frame);
    } else if (auto img = m.instantiate<sensor_msgs::Image>()) {
      BagFrame& f = bag_[stamp];
      f.frame.width = img->width, f.frame.height = img->height;
      if (m.getTopic() == "/capture/draw_ids") {
        f.frame.draw_ids.resize(img->data.size() / 4);
        std::memcpy(f.frame.draw_ids.data(), img->data.data(), img->data.size());
      } else if (m.getTopic() == "/capture/depth/image_raw") {
        f.depth_m.resize(img->data.size() / 4);
        std::memcpy(f.depth_m.data(), img->data.data(), img->data.size());
      }
    }
  };
  const auto by_stamp = viper::test::messagesByStamp(view, pubs, /*camera_info_first=*/false, keep_frame);
  for (const auto& [stamp, messages] : by_stamp) {
    if (!frames_.empty()) {
      const ros::Time prev = frames_.back();
      while (!(hasObjects(prev) && (frames_.size() < 2 || has(kBwd, prev))) && ros::WallTime::now() < deadline)
        ros::WallDuration(0.005).sleep();
    }
    frames_.push_back(stamp);
    for (const auto& [topic, shape] : messages) pubs[topic].publish(shape);
  }
  const size_t n = frames_.size();
  ASSERT_GE(n, static_cast<size_t>(k_ + 3));
  while ((count(kFwd) < n - 1 || count(kFwdVis) < n - 1 || count(kBwd) < n - 1 || count(kBwdVis) < n - 1 ||
          count(kWide) < n - k_ || count(kWideVis) < n - k_ || count(kScene) < n - 1 || odom_.size() < n) &&
         ros::WallTime::now() < deadline)
    ros::WallDuration(0.01).sleep();

  // The service while the window still holds the last frames (checked below against the topics).
  ros::ServiceClient client = nh.serviceClient<viper::Correspondences>("/ground_truth/flow/correspondences");
  auto ask = [&](const ros::Time& a, const ros::Time& b) {
    viper::Correspondences srv;
    srv.request.stamp_a = a, srv.request.stamp_b = b;
    EXPECT_TRUE(client.call(srv)) << "service call failed";
    return srv.response;
  };
  const auto consecutive = ask(frames_[n - 2], frames_[n - 1]);
  const auto wide = ask(frames_[n - 1 - k_], frames_[n - 1]);
  const auto backwards_far = ask(frames_[n - 1], frames_[n - 5]);
  const auto not_held = ask(frames_[0], frames_[n - 1]);

  std::lock_guard<std::mutex> lock(mutex_);
  // Stamps: forward flow of frame f has f's stamp, backward flow (f+1 -> f) has f+1's, wide flow
  // (f -> f+k) has f's.
  auto stamps = [&](const std::string& t) {
    std::vector<ros::Time> s;
    for (const auto& [stamp, img] : images_[t]) s.push_back(stamp);
    return s;
  };
  const std::vector<ros::Time> first(frames_.begin(), frames_.end() - 1), rest(frames_.begin() + 1, frames_.end()),
      wide_first(frames_.begin(), frames_.end() - k_);
  EXPECT_EQ(stamps(kFwd), first);
  EXPECT_EQ(stamps(kFwdVis), first);
  EXPECT_EQ(stamps(kBwd), rest);
  EXPECT_EQ(stamps(kBwdVis), rest);
  EXPECT_EQ(stamps(kWide), wide_first);
  EXPECT_EQ(stamps(kWideVis), wide_first);
  EXPECT_EQ(stamps(kScene), first);
  const uint32_t w = bag_[frames_[0]].frame.width, h = bag_[frames_[0]].frame.height;
  for (const auto& [t, by_stamp] : images_) {
    const bool is_flow = t == kFwd || t == kBwd || t == kWide;
    for (const auto& [stamp, img] : by_stamp) {
      EXPECT_EQ(img.msg->width, w) << t;
      EXPECT_EQ(img.msg->height, h) << t;
      EXPECT_EQ(img.msg->encoding, t == kScene ? "32FC4" : is_flow ? "32FC2" : "mono8") << t;
      EXPECT_EQ(img.msg->data.size(), static_cast<size_t>(w) * h * (t == kScene ? 16 : is_flow ? 8 : 1)) << t;
    }
  }
  for (size_t i = 0; i + 1 < n; ++i)
    if (!images_[kFwd].count(frames_[i]) || !images_[kBwd].count(frames_[i + 1]) ||
        !images_[kFwdVis].count(frames_[i]) || !images_[kBwdVis].count(frames_[i + 1]))
      FAIL() << "missing flow for frame pair " << i;
  for (size_t i = 0; i + k_ < n; ++i)
    if (!images_[kWide].count(frames_[i]) || !images_[kWideVis].count(frames_[i])) FAIL() << "missing wide flow " << i;

  std::vector<double> fb_err, fb_err_non_rigid, static_err, wide_err, scene_err, scene_static;
  size_t scene_mask_differs = 0;
  size_t surface = 0, valid = 0, visible = 0, moving_objects = 0, non_rigid = 0, non_rigid_valid = 0;
  std::map<int32_t, double> moving_median;  // per moving track, worst (lowest) median over frames
  std::map<int32_t, std::string> track_class;
  for (size_t i = 0; i + 1 < n; ++i) {
    const BagFrame& a = bag_[frames_[i]];
    const BagFrame& b = bag_[frames_[i + 1]];
    const Received& fwd = image(kFwd, frames_[i]);
    const Received& fwd_vis = image(kFwdVis, frames_[i]);
    const Received& bwd = image(kBwd, frames_[i + 1]);
    const Received& bwd_vis = image(kBwdVis, frames_[i + 1]);
    // Surfaces by object: static ones keep their world pose from a to b; moving ones change it.
    const viper::ObjectArray& oa = *objects_.at(frames_[i]);
    const viper::ObjectArray& ob = *objects_.at(frames_[i + 1]);
    std::map<int32_t, const viper::Object*> b_tracks;
    for (const auto& o : ob.objects)
      if (o.track_id > 0) b_tracks[o.track_id] = &o;
    enum Motion : uint8_t { kUnknown, kStatic, kMoving };
    std::vector<Motion> draw_motion(a.frame.draws.size(), kUnknown);
    std::vector<int32_t> draw_track(a.frame.draws.size(), 0);
    // Untracked draws are static where b has the same mesh at the same world matrix.
    for (size_t d = 0; d < a.frame.draws.size(); ++d) {
      for (const viper::DrawRecord& db : b.frame.draws)
        if (db.mesh_key == a.frame.draws[d].mesh_key && db.world == a.frame.draws[d].world) draw_motion[d] = kStatic;
    }
    // Tracked objects are static where their world pose stays, moving where it changes.
    for (const auto& o : oa.objects) {
      if (o.track_id <= 0) continue;
      auto it = b_tracks.find(o.track_id);
      Motion motion = kUnknown;
      if (it != b_tracks.end()) {
        const auto &p = o.world_pose, &q = it->second->world_pose;
        const double moved = std::hypot(p.position.x - q.position.x, p.position.y - q.position.y,
                                        p.position.z - q.position.z);
        const double turned = std::abs(p.orientation.x - q.orientation.x) + std::abs(p.orientation.y - q.orientation.y) +
                              std::abs(p.orientation.z - q.orientation.z) + std::abs(p.orientation.w - q.orientation.w);
        if (moved > 1e-3 || turned > 1e-4) motion = kMoving;
        if (moved == 0.0 && turned == 0.0) motion = kStatic;
      }
      for (uint32_t d : o.draws) {
        if (d >= draw_motion.size()) continue;
        draw_motion[d] = motion;
        draw_track[d] = o.track_id;
        track_class[o.track_id] = o.class_name;
      }
    }
    // Non-rigid draws move on their own: neither static nor rigidly moving.
    for (size_t d = 0; d < a.frame.draws.size(); ++d)
      if (!a.frame.draws[d].deformed_clip_xyzw.empty()) draw_motion[d] = kUnknown;
    // The camera's ego-motion, from the frames' own matrices: the flow of a static point.
    const auto cam_a = viper::chooseFrameCamera(a.frame), cam_b = viper::chooseFrameCamera(b.frame);
    ASSERT_TRUE(cam_a && cam_b);
    const viper::PinholeIntrinsics ka = viper::intrinsicsFromGlProjection(cam_a->projection, w, h);
    const viper::PinholeIntrinsics kb = viper::intrinsicsFromGlProjection(cam_b->projection, w, h);
    const Eigen::Isometry3d b_from_a = viper::opticalFromWorld(cam_b->view) * viper::opticalFromWorld(cam_a->view).inverse();
    const Eigen::Matrix3d ka_inv = ka.K().inverse();
    // The scene flow a -> b: p + scene flow (a's optical frame) lands where the flow does in b.
    const float* scene = reinterpret_cast<const float*>(image(kScene, frames_[i]).msg->data.data());
    const Eigen::Isometry3d scene_b_from_a = viper::opticalMotion(cam_b->view, cam_a->view);
    std::map<int32_t, std::vector<double>> moving_err;

    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        if (a.frame.draw_ids[p] == 0) continue;
        const uint32_t draw = a.frame.draw_ids[p] - 1;
        const bool deformed = !a.frame.draws[draw].deformed_clip_xyzw.empty();
        ++surface;
        non_rigid += deformed;
        const Eigen::Vector2d f(fwd.uv()[2 * p], fwd.uv()[2 * p + 1]);
        const float* sf = scene + 4 * p;
        for (int c = 0; c < 4; ++c) scene_mask_differs += std::isfinite(sf[c]) != f.allFinite();
        if (f.allFinite() && std::isfinite(sf[0]) && std::isfinite(a.depth_m[p])) {
          const Eigen::Vector3d pa = a.depth_m[p] * (ka_inv * Eigen::Vector3d(x, y, 1.0));
          const Eigen::Vector3d moved = pa + Eigen::Vector3d(sf[0], sf[1], sf[2]);
          scene_err.push_back((kb.project(scene_b_from_a * moved) - (Eigen::Vector2d(x, y) + f)).norm());
          if (draw_motion[draw] == kStatic && !deformed) scene_static.push_back(Eigen::Vector3d(sf[0], sf[1], sf[2]).norm());
        }
        if (!f.allFinite()) continue;
        ++valid;
        non_rigid_valid += deformed;
        if (fwd_vis.mask()[p] != 255) continue;
        ++visible;
        const Eigen::Vector2d start(x, y), target = start + f;
        if (auto back = sampleSameSurface(bwd.uv(), bwd_vis.mask(), b.frame.draw_ids, w, h, target.x(), target.y()))
          (deformed ? fb_err_non_rigid : fb_err).push_back((target + *back - start).norm());
        if (draw_motion[draw] == kUnknown || !std::isfinite(a.depth_m[p])) continue;
        const Eigen::Vector3d pa = a.depth_m[p] * (ka_inv * Eigen::Vector3d(x, y, 1.0));
        const Eigen::Vector2d ego = kb.project(b_from_a * pa) - start;
        const double err = (f - ego).norm();
        if (draw_motion[draw] == kStatic) {
          static_err.push_back(err);
        } else {
          moving_err[draw_track[draw]].push_back(err);
        }
      }
    }
    for (auto& [track, errs] : moving_err) {
      if (errs.size() < 50) continue;  // a sliver: too few pixels to say
      ++moving_objects;
      const double med = percentiles(errs).median;
      auto it = moving_median.find(track);
      moving_median[track] = it == moving_median.end() ? med : std::min(it->second, med);
    }

    // Wide baseline: f -> f+k against k composed single steps, where every step is visible and
    // lands inside one surface.
    if (i + k_ < n) {
      const Received& wf = image(kWide, frames_[i]);
      const Received& wv = image(kWideVis, frames_[i]);
      for (size_t p = 0; p < static_cast<size_t>(w) * h; ++p) {
        if (wv.mask()[p] != 255 || fwd_vis.mask()[p] != 255) continue;
        Eigen::Vector2d pos(p % w, p / w);
        pos += Eigen::Vector2d(fwd.uv()[2 * p], fwd.uv()[2 * p + 1]);
        bool ok = true;
        for (int s = 1; s < k_ && ok; ++s) {
          const Received& step = image(kFwd, frames_[i + s]);
          const Received& step_vis = image(kFwdVis, frames_[i + s]);
          auto d = sampleSameSurface(step.uv(), step_vis.mask(), bag_[frames_[i + s]].frame.draw_ids, w, h, pos.x(),
                                     pos.y());
          if (d) pos += *d;
          ok = d.has_value();
        }
        if (!ok) continue;
        const Eigen::Vector2d direct = Eigen::Vector2d(p % w, p / w) + Eigen::Vector2d(wf.uv()[2 * p], wf.uv()[2 * p + 1]);
        wide_err.push_back((pos - direct).norm());
      }
    }
  }

  const double valid_fraction = static_cast<double>(valid) / surface;
  const Percentiles fb = percentiles(fb_err), fb_nr = percentiles(fb_err_non_rigid), st = percentiles(static_err), wd = percentiles(wide_err);
  std::cout << "[flow_tester] " << n << " frames " << w << "x" << h << ": surface pixels with forward flow "
            << valid_fraction << " (" << valid << "/" << surface << "), visible in the next frame " << visible << "\n"
            << "[flow_tester] non-rigid surface pixels with forward flow " << non_rigid_valid << "/" << non_rigid << "\n"
            << "[flow_tester] forward-backward round trip (non-occluded, same surface), rigid: " << describe(fb) << "\n"
            << "[flow_tester] forward-backward round trip (non-occluded, same surface), non-rigid: " << describe(fb_nr)
            << "\n"
            << "[flow_tester] static surfaces vs ego-motion flow: " << describe(st) << "\n"
            << "[flow_tester] wide baseline k=" << k_ << " vs composed single steps: " << describe(wd) << "\n"
            << "[flow_tester] scene flow: p + scene flow projected into the next frame vs pixel + flow: "
            << describe(percentiles(scene_err)) << "; static surfaces' |scene flow| (m): "
            << describe(percentiles(scene_static)) << "\n";
  for (const auto& [track, med] : moving_median)
    std::cout << "[flow_tester] moving track " << track << " (" << track_class[track] << "): lowest per-frame median |flow - ego-motion flow| " << med
              << " px\n";
  EXPECT_GE(valid_fraction, 0.95) << "surface pixels without flow";
  EXPECT_GE(fb.n, (valid - non_rigid_valid) / 2) << "too few pixels for the round trip";
  EXPECT_LT(fb.median, 0.01) << describe(fb);
  EXPECT_LT(fb.p90, 0.05) << describe(fb);
  EXPECT_GE(non_rigid, 1000u) << "no non-rigid surface in the bag: the non-rigid checks say nothing";
  EXPECT_GE(non_rigid_valid, non_rigid * 95 / 100) << "non-rigid pixels without flow";
  EXPECT_GE(fb_nr.n, non_rigid / 4) << "too few non-rigid pixels for the round trip";
  EXPECT_LT(fb_nr.median, 0.01) << "non-rigid: " << describe(fb_nr);
  EXPECT_GE(st.n, surface / 4) << "too few static pixels";
  EXPECT_LT(st.median, 0.01) << "static surfaces: " << describe(st);
  EXPECT_LT(st.p99, 0.05) << "static surfaces: " << describe(st);
  EXPECT_GE(moving_objects, 1u) << "no moving object seen: the check says nothing";
  for (const auto& [track, med] : moving_median) EXPECT_GT(med, 0.1) << "moving track " << track << " flows like static";
  EXPECT_GE(wd.n, visible / (4 * (n - 1))) << "too few pixels for the wide-baseline check";
  EXPECT_LT(wd.median, 0.01) << describe(wd);
  EXPECT_LT(wd.p90, 0.05) << describe(wd);
  // Scene flow: where the flow is and nowhere else, consistent with it (both from the same double
  // point; p here from the depth topic's float metres and the pinhole intrinsics), and static
  // surfaces do not move.
  const Percentiles sc = percentiles(scene_err), ss = percentiles(scene_static);
  EXPECT_EQ(scene_mask_differs, 0u) << "scene flow NaN where the flow is not, or the reverse";
  EXPECT_GE(sc.n, valid * 9 / 10) << "too few pixels for the scene flow check";
  EXPECT_LT(sc.p99, 1e-3) << describe(sc);
  EXPECT_GE(ss.n, surface / 4) << "too few static pixels for the scene flow check";
  EXPECT_LT(ss.p99, 1e-5) << "static |scene flow| (m): " << describe(ss);

  // The service: the same flow as the topics, a pose that agrees with odometry, and a refusal for
  // a frame no longer held.
  ASSERT_TRUE(consecutive.success) << consecutive.message;
  EXPECT_EQ(consecutive.flow.data, image(kFwd, frames_[n - 2]).msg->data) << "service differs from flow/forward";
  EXPECT_EQ(consecutive.visible.data, image(kFwdVis, frames_[n - 2]).msg->data);
  EXPECT_EQ(consecutive.flow.header.stamp, frames_[n - 2]);
  ASSERT_TRUE(wide.success) << wide.message;
  EXPECT_EQ(wide.flow.data, image(kWide, frames_[n - 1 - k_]).msg->data) << "service differs from flow/wide";
  ASSERT_TRUE(backwards_far.success) << backwards_far.message;
  EXPECT_EQ(backwards_far.flow.encoding, "32FC2");
  EXPECT_EQ(backwards_far.visible.encoding, "mono8");
  EXPECT_FALSE(not_held.success);
  EXPECT_FALSE(not_held.message.empty());
  for (const auto* r : {&consecutive, &wide, &backwards_far}) {
    const ros::Time ta = r == &backwards_far ? frames_[n - 1] : (r == &wide ? frames_[n - 1 - k_] : frames_[n - 2]);
    const ros::Time tb = r == &backwards_far ? frames_[n - 5] : frames_[n - 1];
    ASSERT_TRUE(r->pose_valid);
    ASSERT_TRUE(odom_.count(ta) && odom_.count(tb)) << "no odometry for the frames";
    const Eigen::Isometry3d map_a = viper::fromPoseMsg(odom_[ta]->pose.pose) * viper::bodyFromOptical();
    const Eigen::Isometry3d map_b = viper::fromPoseMsg(odom_[tb]->pose.pose) * viper::bodyFromOptical();
    const Eigen::Isometry3d expected = map_a.inverse() * map_b;
    const auto& t = r->b_in_a;
    const Eigen::Vector3d got_t(t.translation.x, t.translation.y, t.translation.z);
    const Eigen::Quaterniond got_q(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
    const double dt = (got_t - expected.translation()).norm();
    const double dr = Eigen::AngleAxisd(got_q.toRotationMatrix().transpose() * expected.linear()).angle();
    std::cout << "[flow_tester] service pose " << ta << " -> " << tb << ": camera moved "
              << expected.translation().norm() << " m, "
              << Eigen::AngleAxisd(expected.linear()).angle() << " rad; vs odometry " << dt << " m, " << dr
              << " rad\n";
    EXPECT_GT(expected.translation().norm(), 0.01) << "the camera does not move: the pose check says nothing";
    EXPECT_LT(dt, 1e-4);
    EXPECT_LT(dr, 1e-5);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "flow_tester");
}
