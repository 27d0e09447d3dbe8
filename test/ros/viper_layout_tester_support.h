// What the VIPER layout tests share: everything a subscriber received by topic, the player's
// /rosout lines, waiting on a condition, running a command, comparing two folders.
#pragma once

#include "tester_main.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>

#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace {

const char* kImageTopics[] = {"capture/color/image_raw",     "ground_truth/semantic",
                              "ground_truth/instance_ids",   "ground_truth/instances_viper",
                              "ground_truth/flow/forward",   "ground_truth/flow/backward"};

// Everything received, by topic.
class Received {
 public:
  void subscribe(ros::NodeHandle& nh, const std::string& ns) {
    for (const char* t : kImageTopics) {
      const std::string topic = ns + t;
      subs_.push_back(nh.subscribe<sensor_msgs::Image>(topic, 200, [this, topic](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        images[topic].push_back(m);
        arrival[topic].push_back(ros::WallTime::now());
      }));
    }
    infos_sub_ = nh.subscribe<sensor_msgs::CameraInfo>(ns + "capture/color/camera_info", 200,
                                                       [this](const sensor_msgs::CameraInfoConstPtr& m) {
                                                         std::lock_guard<std::mutex> lock(mutex_);
                                                         infos.push_back(m);
                                                       });
    odom_sub_ = nh.subscribe<nav_msgs::Odometry>(ns + "ground_truth/odom", 200, [this](const nav_msgs::OdometryConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      odoms.push_back(m);
    });
    boxes_sub_ = nh.subscribe<viper::Box3DArray>(ns + "ground_truth/boxes", 200, [this](const viper::Box3DArrayConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      boxes.push_back(m);
    });
    optical_sub_ = nh.subscribe<viper::Box3DArray>(ns + "ground_truth/boxes_optical", 200,
                                                   [this](const viper::Box3DArrayConstPtr& m) {
                                                     std::lock_guard<std::mutex> lock(mutex_);
                                                     boxes_optical.push_back(m);
                                                   });
  }
  bool connected() const {
    for (const auto& s : subs_)
      if (s.getNumPublishers() == 0) return false;
    return infos_sub_.getNumPublishers() && odom_sub_.getNumPublishers() && boxes_sub_.getNumPublishers() &&
           optical_sub_.getNumPublishers();
  }
  size_t count(const std::string& topic) {
    std::lock_guard<std::mutex> lock(mutex_);
    return images[topic].size();
  }
  // Whether every topic has at least its count: image topics by name, the others as "odom",
  // "camera_info", "boxes" and "boxes_optical". Each topic has its own connection, so one topic's
  // last message can come after another's.
  bool reached(const std::map<std::string, size_t>& counts) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::map<std::string, size_t> others = {
        {"odom", odoms.size()}, {"camera_info", infos.size()}, {"boxes", boxes.size()}, {"boxes_optical", boxes_optical.size()}};
    for (const auto& [topic, n] : counts) {
      const auto other = others.find(topic);
      if ((other != others.end() ? other->second : images[topic].size()) < n) return false;
    }
    return true;
  }

  std::mutex mutex_;
  std::map<std::string, std::vector<sensor_msgs::ImageConstPtr>> images;
  std::map<std::string, std::vector<ros::WallTime>> arrival;
  std::vector<sensor_msgs::CameraInfoConstPtr> infos;
  std::vector<nav_msgs::OdometryConstPtr> odoms;
  std::vector<viper::Box3DArrayConstPtr> boxes, boxes_optical;

 private:
  std::vector<ros::Subscriber> subs_;
  ros::Subscriber infos_sub_, odom_sub_, boxes_sub_, optical_sub_;
};

using viper::test::waitFor;

// The player's /rosout lines.
class Rosout {
 public:
  explicit Rosout(ros::NodeHandle& nh) {
    sub_ = nh.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::LogConstPtr& m) {
      if (m->msg.rfind("player: ", 0) != 0) return;
      std::lock_guard<std::mutex> lock(mutex_);
      lines_.push_back(*m);
    });
  }
  size_t publishers() const { return sub_.getNumPublishers(); }
  std::vector<rosgraph_msgs::Log> lines() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lines_;
  }
  bool has(const std::string& text) {
    for (const auto& l : lines())
      if (l.msg.find(text) != std::string::npos) return true;
    return false;
  }
  size_t errors() {
    size_t n = 0;
    for (const auto& l : lines()) n += l.level == rosgraph_msgs::Log::ERROR;
    return n;
  }

 private:
  ros::Subscriber sub_;
  std::mutex mutex_;
  std::vector<rosgraph_msgs::Log> lines_;
};

bool sameFloats(const sensor_msgs::Image& m, const std::vector<float>& expected) {
  if (m.data.size() != expected.size() * 4) return false;
  return std::memcmp(m.data.data(), expected.data(), m.data.size()) == 0;
}

// Runs a shell command; its exit code, or -1.
int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Every file under `a` is under `b` with the same bytes, and the other way round.
void expectSameTree(const std::filesystem::path& a, const std::filesystem::path& b,
                    const std::function<bool(const std::string&)>& ignore = {}) {
  namespace fs = std::filesystem;
  auto files = [&ignore](const fs::path& root) {
    std::map<std::string, std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(root))
      if (e.is_regular_file() && !(ignore && ignore(fs::relative(e.path(), root).string())))
        out[fs::relative(e.path(), root).string()] = e.path().string();
    return out;
  };
  const auto fa = files(a), fb = files(b);
  ASSERT_FALSE(fa.empty()) << a;
  for (const auto& [rel, path] : fa) {
    const auto other = fb.find(rel);
    if (other == fb.end()) {
      ADD_FAILURE() << rel << " is in " << a << " but not in " << b;
      continue;
    }
    EXPECT_EQ(run("cmp -s " + path + " " + other->second), 0) << rel << " differs";
  }
  for (const auto& [rel, path] : fb) EXPECT_TRUE(fa.count(rel)) << rel << " is in " << b << " but not in " << a;
}

}  // namespace
