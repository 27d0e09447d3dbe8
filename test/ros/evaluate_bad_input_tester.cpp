// Feeds two evaluate nodes small synthetic frames without draw lists: bad predictions and bad
// ground truth (wrong encodings, sizes, a broken quaternion) must each be reported on /rosout
// naming the topic and skipped, the good frames around them scored; one node takes the estimate
// from tf instead of a topic. Both nodes then go idle, write their report and shut down
// (~shutdown_after_idle_s); the reports are checked. Every step waits for its event (a node
// connected, a line logged, a score published, a node gone), each with timeout_s as the cap of a hang:
// a loaded machine only makes it slower.
// Private parameters: report_dir (of /evaluate), tf_report_dir (of /evaluate_tf), timeout_s (60).
#include "tester_main.h"
#include "../common/process_util.h"

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <opencv_apps/FlowArrayStamped.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <viper/InstancePredictionArray.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <mutex>

namespace {

using viper::test::readFile;

constexpr uint32_t kW = 4, kH = 3;

sensor_msgs::Image image(const std::string& encoding, uint32_t w, uint32_t h, size_t bpp, const ros::Time& t) {
  sensor_msgs::Image m;
  m.header.stamp = t;
  m.header.frame_id = "camera_optical";
  m.encoding = encoding, m.width = w, m.height = h, m.step = static_cast<uint32_t>(w * bpp);
  m.data.assign(static_cast<size_t>(m.step) * h, 0);
  return m;
}

sensor_msgs::Image flowImage(const ros::Time& t, float u) {
  sensor_msgs::Image m = image("32FC2", kW, kH, 8, t);
  std::vector<float> uv(2 * kW * kH, u);
  std::memcpy(m.data.data(), uv.data(), m.data.size());
  return m;
}

nav_msgs::Odometry odom(const ros::Time& t, double x) {
  nav_msgs::Odometry m;
  m.header.stamp = t;
  m.header.frame_id = "map";
  m.child_frame_id = "camera";
  m.pose.pose.position.x = x;
  m.pose.pose.orientation.w = 1.0;
  return m;
}

// True once `node` sends its /rosout to this node. A subscriber counts a publisher as soon as it
// asks for the connection, the publisher counts the subscriber once the connection is made: what
// the node logs in between never reaches us. Asks the node (its XML-RPC getBusInfo).
bool sendsUsItsRosout(const std::string& node) {
  const std::string me = ros::this_node::getName();
  XmlRpc::XmlRpcValue args, result, uri;
  args[0] = me;
  args[1] = node;
  std::string host;
  uint32_t port = 0;
  if (!ros::master::execute("lookupNode", args, result, uri, false) || uri.getType() != XmlRpc::XmlRpcValue::TypeString ||
      !ros::network::splitURI(static_cast<std::string>(uri), host, port))
    return false;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue request, response;
  request[0] = me;
  if (!client.execute("getBusInfo", request, response) || response.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      response.size() < 3)
    return false;
  // [connection id, the other node, direction, transport, topic, ...] per connection.
  for (int i = 0; i < response[2].size(); ++i) {
    XmlRpc::XmlRpcValue& link = response[2][i];
    if (link.size() > 4 && static_cast<std::string>(link[1]) == me && static_cast<std::string>(link[2]) == "o" &&
        static_cast<std::string>(link[4]) == "/rosout")
      return true;
  }
  return false;
}

class EvaluateBadInput : public ::testing::Test {
 protected:
  std::mutex mutex_;
  std::vector<rosgraph_msgs::Log> logs_;
  std::map<std::string, std::string> scores_;

  bool logged(const std::string& node, const std::string& a, const std::string& b) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& l : logs_)
      if (l.name == node && l.level >= rosgraph_msgs::Log::ERROR && l.msg.find(a) != std::string::npos &&
          l.msg.find(b) != std::string::npos)
        return true;
    return false;
  }
  std::string scores(const std::string& node) {
    std::lock_guard<std::mutex> lock(mutex_);
    return scores_[node];
  }
};

TEST_F(EvaluateBadInput, BadFramesAreReportedAndSkippedGoodOnesScored) {
  ros::NodeHandle nh, pnh("~");
  std::string report_dir, tf_report_dir;
  ASSERT_TRUE(pnh.getParam("report_dir", report_dir));
  ASSERT_TRUE(pnh.getParam("tf_report_dir", tf_report_dir));
  double timeout_s = 60;
  pnh.param("timeout_s", timeout_s, 60.0);
  std::filesystem::remove_all(report_dir);
  std::filesystem::remove_all(tf_report_dir);

  auto gt_sem = nh.advertise<sensor_msgs::Image>("/ground_truth/semantic", 10);
  auto gt_ids = nh.advertise<sensor_msgs::Image>("/ground_truth/instance_ids", 10);
  auto gt_flow = nh.advertise<sensor_msgs::Image>("/ground_truth/flow/forward", 10);
  auto gt_vis = nh.advertise<sensor_msgs::Image>("/ground_truth/flow/forward_visible", 10);
  auto gt_odom = nh.advertise<nav_msgs::Odometry>("/ground_truth/odom", 10);
  auto semantic = nh.advertise<sensor_msgs::Image>("/perception/semantic", 10);
  auto instances = nh.advertise<viper::InstancePredictionArray>("/perception/instances", 10);
  auto flow = nh.advertise<sensor_msgs::Image>("/perception/flow", 10);
  auto sparse = nh.advertise<opencv_apps::FlowArrayStamped>("/perception/flow_sparse", 10);
  auto est_odom = nh.advertise<nav_msgs::Odometry>("/perception/odom", 10);
  auto tf = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
  ros::Subscriber rosout = nh.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::Log::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(*m);
  });
  std::vector<ros::Subscriber> score_subs;
  for (const std::string node : {"/evaluate", "/evaluate_tf"})
    score_subs.push_back(nh.subscribe<std_msgs::String>(node + "/scores", 10, [this, node](const std_msgs::String::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      scores_[node] = m->data;
    }));
  ros::AsyncSpinner spinner(1);
  spinner.start();

  // Each wait has its own cap: one slow step does not eat the time of the next.
  auto wait = [&](const std::function<bool()>& ok) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (!ok() && ros::WallTime::now() < deadline) ros::WallDuration(0.01).sleep();
    return ok();
  };
  ASSERT_TRUE(wait([&] {
    for (const auto* p : {&semantic, &instances, &flow, &sparse, &est_odom})
      if (p->getNumSubscribers() < 1) return false;
    // Both nodes read every ground-truth topic (a frame sent before one of them connected is lost
    // to it) and publish on /rosout (read directly: rostest may run without the aggregator).
    for (const auto* p : {&gt_sem, &gt_ids, &gt_flow, &gt_vis, &gt_odom})
      if (p->getNumSubscribers() < 2) return false;
    return tf.getNumSubscribers() >= 1 && sendsUsItsRosout("/evaluate") && sendsUsItsRosout("/evaluate_tf");
  })) << "evaluate nodes did not connect: prediction subscribers " << semantic.getNumSubscribers() << " "
         << instances.getNumSubscribers() << " " << flow.getNumSubscribers() << " " << sparse.getNumSubscribers() << " "
         << est_odom.getNumSubscribers() << ", ground-truth subscribers " << gt_sem.getNumSubscribers() << " "
         << gt_odom.getNumSubscribers() << ", tf subscribers " << tf.getNumSubscribers() << ", rosout publishers "
         << rosout.getNumPublishers() << " (/rosout sent to us: /evaluate " << sendsUsItsRosout("/evaluate")
         << ", /evaluate_tf " << sendsUsItsRosout("/evaluate_tf") << ")";

  std::vector<ros::Time> t;
  for (int k = 0; k < 6; ++k) t.push_back(ros::Time(100.0 + 0.1 * k));
  auto goodGround = [&](const ros::Time& s, bool flow_ok = true) {
    sensor_msgs::Image sem = image("mono8", kW, kH, 1, s);
    for (size_t i = 0; i < sem.data.size(); ++i) sem.data[i] = i < 6 ? 24 : 3;
    gt_sem.publish(sem);
    sensor_msgs::Image ids = image("32SC1", kW, kH, 4, s);
    gt_ids.publish(ids);
    gt_flow.publish(flowImage(s, 1.0f));
    sensor_msgs::Image vis = flow_ok ? image("mono8", kW, kH, 1, s) : image("mono8", kW + 1, kH, 1, s);
    std::fill(vis.data.begin(), vis.data.end(), 255);
    gt_vis.publish(vis);
  };
  auto sparseAt = [&](const ros::Time& s) {
    opencv_apps::FlowArrayStamped f;
    f.header.stamp = s;
    f.flow.resize(1);
    f.flow[0].point.x = 1, f.flow[0].point.y = 1, f.flow[0].velocity.x = 1, f.flow[0].velocity.y = 1;
    return f;
  };
  auto goodInstances = [&](const ros::Time& s) {
    viper::InstancePredictionArray a;
    a.header.stamp = s;
    return a;
  };
  auto tfAt = [&](const ros::Time& s, double x) {
    geometry_msgs::TransformStamped m;
    m.header.stamp = s;
    m.header.frame_id = "vo_odom";
    m.child_frame_id = "vo_camera";
    m.transform.translation.x = x;
    m.transform.rotation.w = 1.0;
    tf2_msgs::TFMessage msg;
    msg.transforms.push_back(m);
    tf.publish(msg);
  };

  // Frame 0: every prediction broken except the sparse flow.
  goodGround(t[0]);
  gt_odom.publish(odom(t[0], 0.0));
  tfAt(t[0], 0.0);
  semantic.publish(image("rgb8", kW, kH, 3, t[0]));
  viper::InstancePredictionArray bad_instances = goodInstances(t[0]);
  bad_instances.instances.resize(1);
  bad_instances.instances[0].class_id = 24, bad_instances.instances[0].score = 1;
  bad_instances.instances[0].x_offset = 3;
  bad_instances.instances[0].mask = image("mono8", 2, 2, 1, t[0]);
  instances.publish(bad_instances);
  flow.publish(image("32FC1", kW, kH, 4, t[0]));
  sparse.publish(sparseAt(t[0]));
  nav_msgs::Odometry broken = odom(t[0], 0.0);
  broken.pose.pose.orientation.w = 0.0;
  est_odom.publish(broken);
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/perception/semantic", "encoding is 'rgb8', expected mono8 (4x3)"); }));
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/perception/instances", "instance 0 mask 2x2 at (3, 0) leaves the 4x3 frame"); }));
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/perception/flow", "encoding is '32FC1', expected 32FC2 (4x3)"); }));
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/perception/odom", "quaternion has norm 0"); }));

  // Frame 1: broken ground truth (semantic as 32SC1, visibility mask of another size).
  sensor_msgs::Image bad_sem = image("32SC1", kW, kH, 4, t[1]);
  gt_sem.publish(bad_sem);
  gt_ids.publish(image("32SC1", kW, kH, 4, t[1]));
  gt_flow.publish(flowImage(t[1], 1.0f));
  gt_vis.publish(image("mono8", kW + 1, kH, 1, t[1]));
  gt_odom.publish(odom(t[1], 0.5));
  tfAt(t[1], 0.5);
  semantic.publish(image("mono8", kW, kH, 1, t[1]));
  instances.publish(goodInstances(t[1]));
  flow.publish(flowImage(t[1], 1.0f));
  sparse.publish(sparseAt(t[1]));
  est_odom.publish(odom(t[1], 0.5));
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/ground_truth/semantic", "encoding is '32SC1', expected mono8 (4x3)"); }));
  EXPECT_TRUE(wait([&] { return logged("/evaluate", "/ground_truth/flow/forward_visible", "size is 5x3, expected 4x3"); }));

  // Frames 2..5: all good. Semantic: the car pixels predicted as road on frame 2 only.
  for (int k = 2; k < 6; ++k) {
    goodGround(t[k]);
    gt_odom.publish(odom(t[k], 0.5 * k));
    tfAt(t[k], 0.5 * k);
    sensor_msgs::Image pred = image("mono8", kW, kH, 1, t[k]);
    for (size_t i = 0; i < pred.data.size(); ++i) pred.data[i] = i < 6 && k != 2 ? 24 : 3;
    semantic.publish(pred);
    instances.publish(goodInstances(t[k]));
    flow.publish(flowImage(t[k], 1.0f));
    sparse.publish(sparseAt(t[k]));
    est_odom.publish(odom(t[k], 0.5 * k));
  }
  // Scored: semantic, instances, flow 4 (frames 2-5); sparse 5 (0, 2-5); poses 5 (1-5); the tf
  // node's poses 6.
  EXPECT_TRUE(wait([&] {
    const std::string s = scores("/evaluate");
    return s.find("  semantic: {frames: 4,") != std::string::npos && s.find("  instances: {frames: 4") != std::string::npos &&
           s.find("  flow: {frames: 4,") != std::string::npos && s.find("  flow_sparse: {frames: 5,") != std::string::npos &&
           s.find("  odometry: {poses: 5,") != std::string::npos;
  })) << scores("/evaluate");
  EXPECT_TRUE(wait([&] { return scores("/evaluate_tf").find("  odometry: {poses: 6,") != std::string::npos; }))
      << scores("/evaluate_tf");

  // Idle: both write their report and shut down; the reports are complete once the nodes are gone.
  const std::string summary = report_dir + "/summary.md", tf_summary = tf_report_dir + "/summary.csv";
  ASSERT_TRUE(wait([&] { return score_subs[0].getNumPublishers() == 0 && score_subs[1].getNumPublishers() == 0; }))
      << "the nodes did not shut down after going idle";
  ASSERT_TRUE(std::filesystem::exists(summary) && std::filesystem::exists(tf_summary))
      << "no report after the nodes went idle";
  const std::string md = readFile(summary);
  EXPECT_NE(md.find("Frames scored: semantic 4, instances 4, dense flow 4, sparse flow 5, odometry poses 5."),
            std::string::npos)
      << md;
  // Frames 2-5, 6 car and 6 road px each; frame 2's car called road: car IoU 18/24, road
  // 24/(24+6), mean 77.5.
  EXPECT_NE(md.find("| fog | 77.50 | - | - | 0.000 | 100.00 | 0.00 | 0.000 | 100.00 | 0.00 | 0.0000 |"), std::string::npos)
      << md;
  const std::string tf_csv = readFile(tf_summary);
  EXPECT_NE(tf_csv.find("\nfog,0,,0,,,0,,,,,,,0,0,,,,,,,6,2.5,"), std::string::npos) << tf_csv;
  EXPECT_NE(tf_csv.find("\nall,"), std::string::npos) << tf_csv;
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "evaluate_bad_input_tester");
}
