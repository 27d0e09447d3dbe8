// Sends the ground-truth nodes broken frames, each followed by a good one, and checks that every
// broken frame is dropped (no output with its stamp) while the nodes keep running and still
// process the good frames. Cases: draw ids with the wrong encoding, draw ids whose size disagrees
// with the data, a stamp older than the previous frame, a non-rigid (scaled) view matrix, a NaN
// world matrix (the object is skipped, the frame kept), a draw whose mesh never arrived, and
// missing frames (a gap of four frames: the moving car keeps its track id).
#include "tester_draws.h"
#include "tester_main.h"

#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <viper/Box3DArray.h>
#include <viper/DrawList.h>
#include <viper/ObjectArray.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <set>

namespace {

// The cap of every wait: it only bounds a hang (a loaded machine is slow, not broken).
constexpr double kCapS = 60.0;

struct Outputs {
  std::mutex mutex;
  std::set<double> objects, odom, boxes;
  std::map<double, size_t> boxes_count;
  std::map<double, int32_t> car_track;  // the car's track id per stamp
  bool has(std::set<double>& s, const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex);
    return s.count(t.toSec()) > 0;
  }
};

viper::Draw draw(uint32_t index, uint64_t mesh, float x) { return viper::test::draw(index, mesh, x, 4); }

class BadInput : public ::testing::Test {
 protected:
  ros::NodeHandle nh_;
  Outputs out_;
  ros::Publisher draws_pub_, ids_pub_;
  double t_ = 100.0;

  void publish(const viper::DrawList& draws, const sensor_msgs::Image& ids) {
    draws_pub_.publish(draws);
    ids_pub_.publish(ids);
  }
  // A consistent 4x2 frame: a car (mesh 1, labelled car in the test's label table) on a road.
  std::pair<viper::DrawList, sensor_msgs::Image> goodFrame(double t, float car_x = 3.0f) {
    viper::DrawList dl;
    dl.header.stamp = ros::Time(t);
    dl.header.frame_id = "camera_optical";
    dl.draws = {draw(0, 2, 0), draw(1, 1, car_x)};
    sensor_msgs::Image ids;
    ids.header = dl.header;
    ids.width = 4, ids.height = 2, ids.encoding = "32SC1", ids.step = 16;
    const int32_t px[8] = {1, 2, 2, 1, 1, 2, 2, 1};
    ids.data.resize(32);
    std::memcpy(ids.data.data(), px, 32);
    return {dl, ids};
  }
  bool waitFor(std::set<double>& s, const ros::Time& t) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kCapS);
    while (ros::WallTime::now() < deadline) {
      if (out_.has(s, t)) return true;
      ros::WallDuration(0.01).sleep();
    }
    return false;
  }
  // Sends a good frame and waits until every node has answered it: the nodes are alive.
  void expectAlive(const std::string& after) {
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    publish(dl, ids);
    EXPECT_TRUE(waitFor(out_.objects, dl.header.stamp)) << "instances silent after " << after;
    EXPECT_TRUE(waitFor(out_.odom, dl.header.stamp)) << "odometry silent after " << after;
    EXPECT_TRUE(waitFor(out_.boxes, dl.header.stamp)) << "boxes silent after " << after;
  }
};

TEST_F(BadInput, BrokenFramesAreDroppedAndTheNodesKeepRunning) {
  auto keep = [this](std::set<double>& s) {
    return [this, &s](const ros::Time& t) {
      std::lock_guard<std::mutex> lock(out_.mutex);
      s.insert(t.toSec());
    };
  };
  auto on_odom = keep(out_.odom);
  ros::Subscriber s1 = nh_.subscribe<viper::ObjectArray>("/ground_truth/objects", 20, [&](const viper::ObjectArrayConstPtr& m) {
    std::lock_guard<std::mutex> lock(out_.mutex);
    out_.objects.insert(m->header.stamp.toSec());
    for (const viper::Object& o : m->objects)
      if (o.track_id > 0) out_.car_track[m->header.stamp.toSec()] = o.track_id;
  });
  ros::Subscriber s2 = nh_.subscribe<nav_msgs::Odometry>("/ground_truth/odom", 20,
                                                        [&](const nav_msgs::OdometryConstPtr& m) { on_odom(m->header.stamp); });
  ros::Subscriber s3 = nh_.subscribe<viper::Box3DArray>("/ground_truth/boxes", 20, [&](const viper::Box3DArrayConstPtr& m) {
    std::lock_guard<std::mutex> lock(out_.mutex);
    out_.boxes.insert(m->header.stamp.toSec());
    out_.boxes_count[m->header.stamp.toSec()] = m->boxes.size();
  });
  draws_pub_ = nh_.advertise<viper::DrawList>("/capture/draws", 20);
  ids_pub_ = nh_.advertise<sensor_msgs::Image>("/capture/draw_ids", 20);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kCapS);
  while ((draws_pub_.getNumSubscribers() < 1 || ids_pub_.getNumSubscribers() < 1 || s1.getNumPublishers() < 1 ||
          s2.getNumPublishers() < 1 || s3.getNumPublishers() < 1) &&
         ros::WallTime::now() < deadline)
    ros::WallDuration(0.05).sleep();
  ASSERT_GE(s3.getNumPublishers(), 1u) << "ground-truth nodes did not come up";

  // Connections inside the manager may settle a moment after they appear: send good frames until
  // one of them comes out of every node (any one: on a loaded machine an answer may take longer
  // than the pause between two frames).
  bool warm = false;
  std::vector<ros::Time> sent;
  const ros::WallTime warm_deadline = ros::WallTime::now() + ros::WallDuration(kCapS);
  while (!warm && ros::WallTime::now() < warm_deadline) {
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    publish(dl, ids);
    sent.push_back(dl.header.stamp);
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(0.5);
    while (ros::WallTime::now() < until && !warm) {
      for (const ros::Time& t : sent)
        warm = warm || (out_.has(out_.odom, t) && out_.has(out_.objects, t) && out_.has(out_.boxes, t));
      ros::WallDuration(0.01).sleep();
    }
  }
  ASSERT_TRUE(warm) << "no good frame came out of the nodes";
  expectAlive("start");
  // The car's mesh never arrived (no mesh_store): it still gets an object, but no box.
  EXPECT_EQ(out_.boxes_count[t_], 0u);

  {  // draw ids with the wrong encoding
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    ids.encoding = "mono8";
    publish(dl, ids);
    expectAlive("a mono8 draw id image");
    EXPECT_FALSE(out_.has(out_.objects, ros::Time(t_ - 1.0))) << "the mono8 frame was not dropped";
  }
  {  // draw ids whose data is shorter than width x height
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    ids.data.resize(20);
    publish(dl, ids);
    expectAlive("a truncated draw id image");
    EXPECT_FALSE(out_.has(out_.objects, ros::Time(t_ - 1.0))) << "the truncated frame was not dropped";
  }
  {  // a stamp older than the last frame
    auto [dl, ids] = goodFrame(t_ - 0.5);
    publish(dl, ids);
    expectAlive("a frame from the past");
    EXPECT_FALSE(out_.has(out_.odom, ros::Time(t_ - 1.5))) << "odometry took a frame from the past";
    EXPECT_FALSE(out_.has(out_.objects, ros::Time(t_ - 1.5))) << "instances took a frame from the past";
  }
  {  // a view matrix that is not rigid (scaled): odometry drops the frame
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    for (auto& d : dl.draws) d.view[0] = d.view[5] = d.view[10] = 2.0f;
    publish(dl, ids);
    expectAlive("a scaled view matrix");
    EXPECT_FALSE(out_.has(out_.odom, ros::Time(t_ - 1.0))) << "odometry used a scaled view matrix";
  }
  {  // missing frames: the car drives at 0.5 m per frame; four frames never arrive
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_, 3.0f);
    publish(dl, ids);
    ASSERT_TRUE(waitFor(out_.objects, dl.header.stamp)) << "instances silent before the gap";
    t_ += 5.0;
    auto [dl2, ids2] = goodFrame(t_, 5.5f);
    publish(dl2, ids2);
    ASSERT_TRUE(waitFor(out_.objects, dl2.header.stamp)) << "instances silent after missing frames";
    EXPECT_TRUE(waitFor(out_.odom, dl2.header.stamp)) << "odometry silent after missing frames";
    EXPECT_TRUE(waitFor(out_.boxes, dl2.header.stamp)) << "boxes silent after missing frames";
    std::lock_guard<std::mutex> lock(out_.mutex);
    ASSERT_TRUE(out_.car_track.count(t_ - 5.0) && out_.car_track.count(t_)) << "the car has no track id";
    EXPECT_EQ(out_.car_track[t_ - 5.0], out_.car_track[t_]) << "the car lost its id over four missing frames";
  }
  {  // a NaN world matrix: that object is skipped, the frame is kept
    t_ += 1.0;
    auto [dl, ids] = goodFrame(t_);
    dl.draws[1].world[0] = std::nanf("");
    publish(dl, ids);
    EXPECT_TRUE(waitFor(out_.objects, dl.header.stamp)) << "instances dropped a frame with one bad object";
    expectAlive("a NaN world matrix");
  }
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "bad_input_tester");
}
