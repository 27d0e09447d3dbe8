// Scores a fake perception stack with the evaluate node on the committed raw bag, replayed frame by
// frame through replay.launch's ground-truth nodelets. The tester is the fake perception: from the
// ground truth it receives it makes predictions on /perception/*, either the ground truth itself
// (mode "perfect": mIoU 100, AP 100, EPE 0, VO error 0; instance masks cropped to their boxes) or
// corrupted in known ways (mode "corrupted"): semantic ids shifted 3 px to the right, one instance
// class never predicted (masks of the whole frame), zero dense flow, sparse flow 0.25 px off in
// lk_flow's convention, and a trajectory stretched by 10 % given in the optical frame. The
// expected scores of the corrupted run are computed here with separate code, from the ground
// truth the tester saw. The first half of the frames is tagged "day", the rest "rain"
// (DrawList.condition), so every number is checked per condition and over all. Then the tester
// asks evaluate for its report and checks the files.
// Private parameters: bag (path, required), mode (perfect|corrupted), report_dir (evaluate's
// ~report_dir), evaluate (evaluate's node name, "/evaluate"), draws_subscribers (processes that
// read /capture/draws: 2 with evaluate as a node, 1 as a nodelet of replay.launch's manager),
// timeout_s (180).
#include "tester_main.h"
#include "../common/process_util.h"
#include "bag_publishers.h"
#include "evaluate_expect.h"

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/ego_motion.h"
#include "viper/ros/conversions/pose_conversions.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <opencv_apps/FlowArrayStamped.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <topic_tools/shape_shifter.h>
#include <viper/DrawList.h>
#include <viper/InstancePredictionArray.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

namespace {

using namespace evaluate_expect;
using viper::test::readFile;

const std::string kGtSemantic = "/ground_truth/semantic", kGtIds = "/ground_truth/instance_ids",
                  kGtFlow = "/ground_truth/flow/forward", kGtVisible = "/ground_truth/flow/forward_visible",
                  kGtOdom = "/ground_truth/odom";
constexpr int kShiftPx = 3;
constexpr double kSparseBiasPx = 0.25, kStretch = 1.1;

struct Expected {
  SemanticExpect semantic;
  FlowExpect flow_all, flow_noc, sparse_all, sparse_noc;
  std::set<int> instance_classes;  // scored classes with a ground-truth instance of >= 100 px
  std::vector<Eigen::Isometry3d> gt_poses;
};

class EvaluateTest : public ::testing::Test {
 protected:
  std::mutex mutex_;
  bool corrupted_ = false;
  viper::ClassTable classes_ = viper::ClassTable::load(ros::package::getPath("viper") + "/config/viper_classes.csv");
  std::vector<ros::Time> frames_;                         // bag frames, in order
  std::map<ros::Time, std::string> condition_of_;         // what the tester tagged
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> gt_;  // topic -> stamp -> image
  std::map<ros::Time, nav_msgs::Odometry::ConstPtr> gt_odom_;
  std::set<ros::Time> instances_sent_, sparse_sent_;
  int dropped_class_ = -1;  // corrupted: the instance class never predicted
  std::map<std::string, Expected> expected_;  // per condition
  ros::Publisher semantic_pub_, instances_pub_, flow_pub_, sparse_pub_, odom_pub_;
  std::optional<Eigen::Isometry3d> first_pose_;
  std::string last_scores_;

  size_t count(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    return topic == kGtOdom ? gt_odom_.size() : gt_[topic].size();
  }
  bool has(const std::string& topic, const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return topic == kGtOdom ? gt_odom_.count(t) > 0 : gt_[topic].count(t) > 0;
  }

  // Semantic: the ground truth, or shifted right by kShiftPx (the left columns repeat column 0).
  void predictSemantic(const sensor_msgs::Image::ConstPtr& gt) {
    sensor_msgs::Image pred = *gt;
    if (corrupted_) {
      for (uint32_t y = 0; y < gt->height; ++y)
        for (uint32_t x = 0; x < gt->width; ++x)
          pred.data[y * gt->width + x] = gt->data[y * gt->width + (x >= kShiftPx ? x - kShiftPx : 0)];
    }
    Expected& ex = expected_[condition_of_.at(gt->header.stamp)];
    const auto eval = classes_.semanticEvalMask();
    for (size_t i = 0; i < gt->data.size(); ++i) {
      const uint8_t g = gt->data[i], p = pred.data[i];
      if (g >= eval.size() || !eval[g]) continue;
      if (p == g) {
        ++ex.semantic.tp[g];
      } else {
        ++ex.semantic.fn[g];
        if (p < eval.size()) ++ex.semantic.fp[p];
      }
    }
    semantic_pub_.publish(pred);
  }

  // The ground-truth images of topics `a` and `b` at t, the first time both are here and t is not
  // in `predicted` yet (which then holds it); else none.
  std::optional<std::pair<sensor_msgs::Image::ConstPtr, sensor_msgs::Image::ConstPtr>> bothOnce(
      const ros::Time& t, const std::string& a, const std::string& b, std::set<ros::Time>& predicted) {
    const auto in_a = gt_[a].find(t), in_b = gt_[b].find(t);
    if (in_a == gt_[a].end() || in_b == gt_[b].end() || predicted.count(t)) return std::nullopt;
    predicted.insert(t);
    return std::make_pair(in_a->second, in_b->second);
  }

  // Instances: one mask per ground-truth instance id, of its majority class, score 1; corrupted:
  // never the dropped class.
  void predictInstances(const ros::Time& t) {
    const auto gt = bothOnce(t, kGtSemantic, kGtIds, instances_sent_);
    if (!gt) return;
    const sensor_msgs::Image& s = *gt->first;
    const int32_t* id = reinterpret_cast<const int32_t*>(gt->second->data.data());
    std::map<int32_t, std::map<int, uint64_t>> votes;
    for (size_t i = 0; i < s.data.size(); ++i)
      if (id[i] > 0) ++votes[id[i]][s.data[i]];
    viper::InstancePredictionArray msg;
    msg.header = s.header;
    const auto eval = classes_.instanceEvalMask();
    auto majority = [](const std::map<int, uint64_t>& by_class, uint64_t& pixels) {
      int cls = 0;
      uint64_t best = 0;
      pixels = 0;
      for (const auto& [c, n] : by_class) {
        pixels += n;
        if (n > best) best = n, cls = c;
      }
      return cls;
    };
    if (corrupted_ && dropped_class_ < 0) {
      // The class never predicted: the lowest scored class of an instance of >= 100 px in the
      // first frame that has one (before it, no such class was predicted either).
      for (const auto& [instance, by_class] : votes) {
        uint64_t pixels = 0;
        const int cls = majority(by_class, pixels);
        if (static_cast<size_t>(cls) < eval.size() && eval[cls] && pixels >= 100 &&
            (dropped_class_ < 0 || cls < dropped_class_))
          dropped_class_ = cls;
      }
    }
    for (const auto& [instance, by_class] : votes) {
      uint64_t pixels = 0;
      const int cls = majority(by_class, pixels);
      if (static_cast<size_t>(cls) < eval.size() && eval[cls] && pixels >= 100)
        expected_[condition_of_.at(t)].instance_classes.insert(cls);
      if (corrupted_ && cls == dropped_class_) continue;
      viper::InstancePrediction p;
      p.class_id = static_cast<uint8_t>(cls);
      p.score = 1.0f;
      p.mask.header = s.header;
      p.mask.encoding = "mono8";
      if (corrupted_) {  // a full-frame mask
        p.mask.width = s.width, p.mask.height = s.height;
      } else {  // a mask of the instance's box only
        uint32_t x0 = s.width, y0 = s.height, x1 = 0, y1 = 0;
        for (uint32_t y = 0; y < s.height; ++y)
          for (uint32_t x = 0; x < s.width; ++x)
            if (id[y * s.width + x] == instance)
              x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x + 1), y1 = std::max(y1, y + 1);
        p.x_offset = x0, p.y_offset = y0;
        p.mask.width = x1 - x0, p.mask.height = y1 - y0;
      }
      p.mask.step = p.mask.width;
      p.mask.data.resize(static_cast<size_t>(p.mask.width) * p.mask.height);
      for (uint32_t y = 0; y < p.mask.height; ++y)
        for (uint32_t x = 0; x < p.mask.width; ++x)
          p.mask.data[y * p.mask.width + x] = id[(y + p.y_offset) * s.width + x + p.x_offset] == instance ? 255 : 0;
      msg.instances.push_back(std::move(p));
    }
    instances_pub_.publish(msg);
  }

  // Dense flow (the ground truth, or zero) and sparse flow (every 4th pixel of the ground truth,
  // stamped with the next frame as opencv_apps does; corrupted: lk_flow's convention, 0.25 px off).
  void predictFlow(const ros::Time& t) {
    const auto gt = bothOnce(t, kGtFlow, kGtVisible, sparse_sent_);
    if (!gt) return;
    const sensor_msgs::Image& f = *gt->first;
    const float* uv = reinterpret_cast<const float*>(f.data.data());
    const uint8_t* visible = gt->second->data.data();
    Expected& ex = expected_[condition_of_.at(t)];
    sensor_msgs::Image dense = f;
    if (corrupted_) {
      std::vector<float> zero(2 * static_cast<size_t>(f.width) * f.height, 0.0f);
      std::memcpy(dense.data.data(), zero.data(), dense.data.size());
      for (size_t i = 0; i < zero.size() / 2; ++i) {
        if (!std::isfinite(uv[2 * i]) || !std::isfinite(uv[2 * i + 1])) continue;
        const double norm = std::hypot(static_cast<double>(uv[2 * i]), static_cast<double>(uv[2 * i + 1]));
        ex.flow_all.add(norm, norm);
        if (visible[i]) ex.flow_noc.add(norm, norm);
      }
    }
    flow_pub_.publish(dense);

    const auto next = std::upper_bound(frames_.begin(), frames_.end(), t);
    if (next == frames_.end()) return;
    opencv_apps::FlowArrayStamped sparse;
    sparse.header = f.header;
    sparse.header.stamp = *next;
    for (uint32_t y = 0; y < f.height; y += 4)
      for (uint32_t x = 0; x < f.width; x += 4) {
        const size_t i = static_cast<size_t>(y) * f.width + x;
        if (!std::isfinite(uv[2 * i]) || !std::isfinite(uv[2 * i + 1])) continue;
        opencv_apps::Flow v;
        v.velocity.x = uv[2 * i], v.velocity.y = uv[2 * i + 1];
        v.point.x = x, v.point.y = y;
        if (corrupted_) {
          v.point.x += v.velocity.x, v.point.y += v.velocity.y;  // where the feature went
          v.velocity.x += kSparseBiasPx;
          // evaluate keeps the vector as float, like the flow images.
          const double e = std::hypot(static_cast<double>(static_cast<float>(v.velocity.x)) - uv[2 * i],
                                      static_cast<double>(static_cast<float>(v.velocity.y)) - uv[2 * i + 1]);
          const double norm = std::hypot(static_cast<double>(uv[2 * i]), static_cast<double>(uv[2 * i + 1]));
          ex.sparse_all.add(e, norm);
          if (visible[i]) ex.sparse_noc.add(e, norm);
        }
        sparse.flow.push_back(v);
      }
    sparse_pub_.publish(sparse);
  }

  // Odometry: the ground truth, or stretched by 10 % about the first pose and given as the pose of
  // the optical frame.
  void predictOdom(const nav_msgs::Odometry::ConstPtr& gt) {
    nav_msgs::Odometry est = *gt;
    const Eigen::Isometry3d pose = viper::fromPoseMsg(gt->pose.pose);
    expected_[condition_of_.at(gt->header.stamp)].gt_poses.push_back(pose);
    if (corrupted_) {
      if (!first_pose_) first_pose_ = pose;
      Eigen::Isometry3d stretched = pose;
      stretched.translation() = first_pose_->translation() + kStretch * (pose.translation() - first_pose_->translation());
      const Eigen::Isometry3d optical = stretched * viper::bodyFromOptical();
      const Eigen::Quaterniond q(optical.linear());
      est.pose.pose.position.x = optical.translation().x(), est.pose.pose.position.y = optical.translation().y();
      est.pose.pose.position.z = optical.translation().z();
      est.pose.pose.orientation.w = q.w(), est.pose.pose.orientation.x = q.x();
      est.pose.pose.orientation.y = q.y(), est.pose.pose.orientation.z = q.z();
      est.child_frame_id = "camera_optical_estimate";
    }
    odom_pub_.publish(est);
  }
};

TEST_F(EvaluateTest, ScoresMatchWhatThePredictionsDeserve) {
  ros::NodeHandle nh, pnh("~");
  std::string bag_path, mode, report_dir, evaluate_name;
  ASSERT_TRUE(pnh.getParam("bag", bag_path)) << "tester needs ~bag";
  ASSERT_TRUE(pnh.getParam("report_dir", report_dir)) << "tester needs ~report_dir (evaluate's)";
  pnh.param<std::string>("mode", mode, "perfect");
  pnh.param<std::string>("evaluate", evaluate_name, "/evaluate");
  ASSERT_TRUE(mode == "perfect" || mode == "corrupted") << mode;
  corrupted_ = mode == "corrupted";
  double timeout_s = 180;
  pnh.param("timeout_s", timeout_s, 180.0);
  int draws_subscribers = 2;
  pnh.param("draws_subscribers", draws_subscribers, 2);
  std::vector<double> lengths;
  ASSERT_TRUE(nh.getParam(evaluate_name + "/odometry_segment_lengths_m", lengths)) << "set evaluate's segment lengths";
  int step = 10;
  nh.param(evaluate_name + "/odometry_step_frames", step, 10);
  std::filesystem::remove_all(report_dir);

  semantic_pub_ = nh.advertise<sensor_msgs::Image>("/perception/semantic", 50);
  instances_pub_ = nh.advertise<viper::InstancePredictionArray>("/perception/instances", 50);
  flow_pub_ = nh.advertise<sensor_msgs::Image>("/perception/flow", 50);
  sparse_pub_ = nh.advertise<opencv_apps::FlowArrayStamped>("/perception/flow_sparse", 50);
  odom_pub_ = nh.advertise<nav_msgs::Odometry>("/perception/odom", 50);
  std::vector<ros::Subscriber> subs;
  for (const std::string& topic : {kGtSemantic, kGtIds, kGtFlow, kGtVisible}) {
    subs.push_back(nh.subscribe<sensor_msgs::Image>(topic, 100, [this, topic](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      gt_[topic][m->header.stamp] = m;
      if (topic == kGtSemantic) predictSemantic(m);
      if (topic == kGtSemantic || topic == kGtIds) predictInstances(m->header.stamp);
      if (topic == kGtFlow || topic == kGtVisible) predictFlow(m->header.stamp);
    }));
  }
  subs.push_back(nh.subscribe<nav_msgs::Odometry>(kGtOdom, 100, [this](const nav_msgs::Odometry::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    gt_odom_[m->header.stamp] = m;
    predictOdom(m);
  }));
  ros::Subscriber scores_sub = nh.subscribe<std_msgs::String>(evaluate_name + "/scores", 10,
                                                              [this](const std_msgs::String::ConstPtr& m) {
                                                                std::lock_guard<std::mutex> lock(mutex_);
                                                                last_scores_ = m->data;
                                                              });
  ros::AsyncSpinner spinner(1);  // one thread: the fake perception sees its inputs in order
  spinner.start();

  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<std::string, ros::Publisher> pubs = viper::test::advertiseBagTopics(nh, view);
  std::map<ros::Time, viper::DrawList> draws;
  auto keep_draws = [&](const rosbag::MessageInstance& m, const ros::Time& stamp) {
    if (auto d = m.instantiate<viper::DrawList>()) draws[stamp] = *d;
  };
  auto by_stamp = viper::test::messagesByStamp(view, pubs, /*camera_info_first=*/false, keep_draws);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [stamp, msgs] : by_stamp) frames_.push_back(stamp);
    for (size_t i = 0; i < frames_.size(); ++i) condition_of_[frames_[i]] = i < frames_.size() / 2 ? "day" : "rain";
  }
  const size_t n = frames_.size();
  ASSERT_GE(n, 10u);

  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
  auto connected = [&] {
    for (const char* t : {"/capture/draw_ids", "/capture/depth/image_raw", "/capture/primitive_ids"})
      if (pubs[t].getNumSubscribers() < 1) return false;
    // Processes reading the draw lists: one per process, however many nodelets it runs.
    if (pubs["/capture/draws"].getNumSubscribers() < static_cast<uint32_t>(draws_subscribers)) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    for (const auto* p : {&semantic_pub_, &instances_pub_, &flow_pub_, &sparse_pub_, &odom_pub_})
      if (p->getNumSubscribers() < 1) return false;
    return scores_sub.getNumPublishers() > 0 && ros::service::exists(evaluate_name + "/write_report", false);
  };
  while (!connected() && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
  ASSERT_TRUE(connected()) << "ground-truth nodes, evaluate and the tester did not connect within " << timeout_s << " s";

  for (size_t i = 0; i < n; ++i) {
    const ros::Time stamp = frames_[i];
    // Each frame once the previous one came out of the ground-truth nodes and evaluate has
    // scored the one before (so no queue overflows on a busy machine).
    auto caught_up = [&] {
      if (i == 0) return true;
      if (!has(kGtSemantic, frames_[i - 1]) || !has(kGtOdom, frames_[i - 1]) || (i >= 2 && !has(kGtFlow, frames_[i - 2])))
        return false;
      std::lock_guard<std::mutex> lock(mutex_);
      return i < 2 || (framesIn(last_scores_, "semantic") >= static_cast<long>(i - 1) &&
                       framesIn(last_scores_, "odometry") >= static_cast<long>(i - 1));
    };
    while (!caught_up() && ros::WallTime::now() < deadline) ros::WallDuration(0.005).sleep();
    for (const auto& [topic, shape] : by_stamp[stamp]) {
      if (topic == "/capture/draws") {
        viper::DrawList d = draws.at(stamp);
        d.condition = condition_of_.at(stamp);
        pubs[topic].publish(d);
      } else {
        pubs[topic].publish(shape);
      }
    }
  }
  // Everything out of the ground-truth nodes and into evaluate.
  while ((count(kGtSemantic) < n || count(kGtIds) < n || count(kGtOdom) < n || count(kGtFlow) < n - 1 ||
          count(kGtVisible) < n - 1) &&
         ros::WallTime::now() < deadline)
    ros::WallDuration(0.01).sleep();
  auto scored = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    return framesIn(last_scores_, "semantic") == static_cast<long>(n) &&
           framesIn(last_scores_, "instances") == static_cast<long>(n) &&
           framesIn(last_scores_, "flow") == static_cast<long>(n - 1) &&
           framesIn(last_scores_, "flow_sparse") == static_cast<long>(n - 1) &&
           framesIn(last_scores_, "odometry") == static_cast<long>(n);
  };
  while (!scored() && ros::WallTime::now() < deadline) ros::WallDuration(0.02).sleep();
  if (!scored()) {
    std::lock_guard<std::mutex> lock(mutex_);
    FAIL() << "evaluate did not score every frame; running scores:\n" << last_scores_;
  }

  std_srvs::Trigger srv;
  ASSERT_TRUE(ros::service::call(evaluate_name + "/write_report", srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  std::cout << "[evaluate_tester] " << srv.response.message << "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  for (const char* f : {"summary.md", "summary.csv", "semantic_iou.csv", "instance_ap.csv", "flow.csv",
                        "flow_inliers.csv", "odometry.csv", "flow_inliers.png", "odometry_errors.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(report_dir + "/" + f)) << f << " missing in " << report_dir;
  const std::string md = readFile(report_dir + "/summary.md");
  std::cout << md;

  // Expected numbers per condition and over all.
  Expected all;
  for (const auto& [c, ex] : expected_) {
    all.semantic.merge(ex.semantic);
    all.flow_all.merge(ex.flow_all), all.flow_noc.merge(ex.flow_noc);
    all.sparse_all.merge(ex.sparse_all), all.sparse_noc.merge(ex.sparse_noc);
    all.instance_classes.insert(ex.instance_classes.begin(), ex.instance_classes.end());
  }
  ASSERT_FALSE(all.instance_classes.empty()) << "no scored instance of >= 100 px in the bag: AP says nothing";
  const std::string summary = report_dir + "/summary.csv";
  for (const std::string condition : {"day", "rain", "all"}) {
    const auto row = csvRow(summary, condition);
    ASSERT_FALSE(row.empty()) << "no '" << condition << "' row in " << summary;
    const Expected& ex = condition == "all" ? all : expected_.at(condition);
    const size_t frames = condition == "all" ? n : (condition == "day" ? n / 2 : n - n / 2);
    SCOPED_TRACE(condition);
    EXPECT_EQ(number(row, "semantic_frames"), frames);
    EXPECT_EQ(number(row, "instance_frames"), frames);
    EXPECT_EQ(number(row, "odometry_poses"), frames);
    if (!corrupted_) {
      EXPECT_DOUBLE_EQ(number(row, "mean_iou"), 100.0);
      EXPECT_DOUBLE_EQ(number(row, "ap"), 100.0);
      EXPECT_DOUBLE_EQ(number(row, "ap50"), 100.0);
      for (const char* k : {"flow_epe_px", "flow_noc_epe_px", "sparse_epe_px", "sparse_noc_epe_px", "flow_outlier_percent",
                            "sparse_outlier_percent"})
        EXPECT_DOUBLE_EQ(number(row, k), 0.0) << k;
      for (const char* k : {"flow_wauc", "flow_noc_wauc", "sparse_wauc", "sparse_noc_wauc"})
        EXPECT_DOUBLE_EQ(number(row, k), 100.0) << k;
      EXPECT_GT(number(row, "odometry_segments"), 0);
      EXPECT_NEAR(number(row, "odometry_translation_percent"), 0.0, 1e-6);
      EXPECT_NEAR(number(row, "odometry_rotation_deg_per_m"), 0.0, 1e-4);
    } else {
      const double miou = ex.semantic.meanIou(classes_.semanticEvalMask());
      EXPECT_NEAR(number(row, "mean_iou"), miou, 1e-9);
      EXPECT_LT(miou, 99.0) << "the shift should cost something";
      // One of K classes never predicted: AP 0 for it, 100 for the others.
      const size_t k = ex.instance_classes.size();
      const double ap = ex.instance_classes.count(dropped_class_) ? 100.0 * (k - 1) / k : 100.0;
      EXPECT_NEAR(number(row, "ap"), ap, 1e-9) << k << " classes, dropped " << dropped_class_;
      EXPECT_NEAR(number(row, "ap50"), ap, 1e-9);
      EXPECT_NEAR(number(row, "flow_epe_px"), ex.flow_all.epeMean(), 1e-6);
      EXPECT_NEAR(number(row, "flow_wauc"), ex.flow_all.waucPercent(), 1e-6);
      EXPECT_NEAR(number(row, "flow_outlier_percent"), ex.flow_all.outlierPercent(), 1e-9);
      EXPECT_NEAR(number(row, "flow_noc_epe_px"), ex.flow_noc.epeMean(), 1e-6);
      EXPECT_NEAR(number(row, "flow_noc_wauc"), ex.flow_noc.waucPercent(), 1e-6);
      EXPECT_NEAR(number(row, "flow_noc_outlier_percent"), ex.flow_noc.outlierPercent(), 1e-9);
      EXPECT_GT(ex.flow_all.epeMean(), 0.1) << "zero flow should cost something";
      EXPECT_NEAR(number(row, "sparse_epe_px"), ex.sparse_all.epeMean(), 1e-6);
      EXPECT_NEAR(number(row, "sparse_epe_px"), kSparseBiasPx, 1e-4);
      EXPECT_NEAR(number(row, "sparse_wauc"), ex.sparse_all.waucPercent(), 1e-6);
      EXPECT_NEAR(number(row, "sparse_noc_epe_px"), ex.sparse_noc.epeMean(), 1e-6);
      // VO: every trajectory of the condition (all: both), segments as KITTI picks them.
      std::vector<double> ratios;
      for (const auto& [c, e] : expected_)
        if (condition == "all" || c == condition) stretchedSegments(e.gt_poses, lengths, step, kStretch, ratios);
      ASSERT_FALSE(ratios.empty()) << "no VO segment: lengths too long for the bag";
      double mean = 0.0;
      for (double r : ratios) mean += r;
      mean = 100.0 * mean / ratios.size();
      EXPECT_EQ(number(row, "odometry_segments"), ratios.size());
      EXPECT_NEAR(number(row, "odometry_translation_percent"), mean, 1e-6);
      EXPECT_NEAR(number(row, "odometry_rotation_deg_per_m"), 0.0, 1e-4) << "a stretch does not rotate";
    }
  }
  // The per-class tables agree with the headline numbers.
  const std::string ap_csv = readFile(report_dir + "/instance_ap.csv");
  for (int c : all.instance_classes) {
    const std::string name = classes_.at(c).name;
    const std::string expect = corrupted_ && c == dropped_class_ ? ",0,0" : ",100,100";
    EXPECT_NE(ap_csv.find("\nall," + std::to_string(c) + "," + name + expect + "\n"), std::string::npos)
        << name << " in\n" << ap_csv;
  }
  if (!corrupted_) {
    EXPECT_NE(md.find("| **all** | 100.00 | 100.00 | 100.00 | 0.000 | 100.00 | 0.00 | 0.000 | 100.00 | 0.00 | 0.0000 |"),
              std::string::npos);
    // The plug-in metric iIoU (Cityscapes) reads the same topics: perfect predictions score 100.
    const std::string iiou = readFile(report_dir + "/semantic_iiou.csv");
    for (const std::string condition : {"day", "rain", "all"})
      EXPECT_NE(("\n" + iiou).find("\n" + condition + ",-1,mean,100\n"), std::string::npos) << iiou;
  }
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "evaluate_tester");
}
