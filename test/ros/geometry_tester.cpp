// Replays a raw bag into replay.launch's nodelets (instances, normals, labelled_cloud) frame by frame
// and checks the two lazy outputs: each frame gets a normals image (32FC3, the depth's size and
// frame id; a unit normal facing the camera exactly where the frame has a draw and depth, NaN
// elsewhere) and a labelled cloud (fields x y z rgb label instance, organised at ~decimation; z the
// depth, x and y on the pixel's ray, rgb the colour, label and instance the instances node's
// images). Private parameters: bag (path, required), decimation (the cloud node's, 2), timeout_s (120;
// TesterBag).
#include "tester_main.h"
#include "bag_publishers.h"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <topic_tools/shape_shifter.h>

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

namespace {

const std::string kNormals = "/ground_truth/normals", kCloud = "/ground_truth/labelled_cloud",
                  kSemantic = "/ground_truth/semantic", kInstances = "/ground_truth/instance_ids";

// The bag's images of one frame.
struct BagFrame {
  sensor_msgs::Image::ConstPtr depth, draw_ids, color;
  sensor_msgs::CameraInfo::ConstPtr info;
};

template <typename T>
T at(const std::vector<uint8_t>& data, size_t offset) {
  T v;
  std::memcpy(&v, data.data() + offset, sizeof v);
  return v;
}

class GeometryReplay : public testing::Test {
 protected:
  std::mutex mutex_;
  std::map<std::string, std::map<ros::Time, sensor_msgs::Image::ConstPtr>> images_;
  std::map<ros::Time, sensor_msgs::PointCloud2::ConstPtr> clouds_;
  std::map<ros::Time, BagFrame> bag_;

  bool has(const ros::Time& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    return images_[kNormals].count(t) && clouds_.count(t);
  }
};

TEST_F(GeometryReplay, NormalsAndCloudOfEveryFrame) {
  ros::NodeHandle nh, pnh("~");
  int decimation = 2;
  pnh.param("decimation", decimation, 2);
  viper::test::TesterBag bag(nh);
  rosbag::View& view = *bag.view;
  std::map<std::string, ros::Publisher>& pubs = bag.pubs;
  const ros::WallTime deadline = bag.deadline;
  // Nobody listens yet: once both outputs are advertised, neither node reads its inputs (only
  // normals reads the primitive ids, only the cloud the camera info: flow is off).
  ASSERT_TRUE(viper::test::waitFor([] { return viper::test::allAdvertised({kNormals, kCloud}); }, deadline))
      << kNormals << " and " << kCloud << " never advertised";
  EXPECT_EQ(pubs["/capture/primitive_ids"].getNumSubscribers(), 0u) << "normals reads its inputs unasked";
  EXPECT_EQ(pubs["/capture/color/camera_info"].getNumSubscribers(), 0u) << "labelled_cloud reads its inputs unasked";

  std::vector<ros::Subscriber> subs;
  for (const std::string& t : {kNormals, kSemantic, kInstances})
    subs.push_back(nh.subscribe<sensor_msgs::Image>(t, 100, [this, t](const sensor_msgs::Image::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      images_[t][m->header.stamp] = m;
    }));
  subs.push_back(nh.subscribe<sensor_msgs::PointCloud2>(kCloud, 100, [this](const sensor_msgs::PointCloud2::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    clouds_[m->header.stamp] = m;
  }));
  ros::AsyncSpinner spinner(2);
  spinner.start();

  // The outputs are lazy: the nodes subscribe to the capture's topics once this tester listens.
  // Nodelets of one manager share a connection a topic; only normals reads the primitive ids and only
  // the cloud the camera info (flow is off), and each subscribes to all its inputs at once.
  auto connected = [&] {
    for (const char* t : {"/capture/draws", "/capture/draw_ids", "/capture/primitive_ids", "/capture/depth/image_raw",
                          "/capture/color/image_raw", "/capture/color/camera_info"})
      if (pubs[t].getNumSubscribers() < 1) return false;
    for (const auto& s : subs)
      if (s.getNumPublishers() < 1) return false;
    return true;
  };
  ASSERT_TRUE(viper::test::waitFor(connected, deadline)) << "normals and labelled_cloud did not subscribe";

  const auto by_stamp = viper::test::messagesByStamp(view, pubs, false, [this](const rosbag::MessageInstance& m,
                                                                                const ros::Time& stamp) {
    const std::string& topic = m.getTopic();
    if (topic == "/capture/depth/image_raw") bag_[stamp].depth = m.instantiate<sensor_msgs::Image>();
    if (topic == "/capture/draw_ids") bag_[stamp].draw_ids = m.instantiate<sensor_msgs::Image>();
    if (topic == "/capture/color/image_raw") bag_[stamp].color = m.instantiate<sensor_msgs::Image>();
    if (topic == "/capture/color/camera_info") bag_[stamp].info = m.instantiate<sensor_msgs::CameraInfo>();
  });
  for (const auto& [stamp, messages] : by_stamp) {
    for (const auto& [topic, shape] : messages) pubs[topic].publish(shape);
    EXPECT_TRUE(viper::test::waitFor([&] { return has(stamp); }, deadline)) << "no normals or cloud at " << stamp;
  }
  ASSERT_GE(bag_.size(), 10u);

  std::unique_lock<std::mutex> lock(mutex_);
  size_t normal_pixels = 0, points = 0;
  for (const auto& [stamp, f] : bag_) {
    ASSERT_TRUE(f.depth && f.draw_ids && f.color && f.info) << "bag frame " << stamp;
    const uint32_t w = f.depth->width, h = f.depth->height;
    const double fx = f.info->K[0], fy = f.info->K[4], cx = f.info->K[2], cy = f.info->K[5];
    const float* depth = reinterpret_cast<const float*>(f.depth->data.data());
    const uint32_t* ids = reinterpret_cast<const uint32_t*>(f.draw_ids->data.data());

    const sensor_msgs::Image& n = *images_[kNormals].at(stamp);
    ASSERT_EQ(n.encoding, "32FC3");
    ASSERT_EQ(n.width, w);
    ASSERT_EQ(n.height, h);
    ASSERT_EQ(n.step, 12 * w);
    ASSERT_EQ(n.data.size(), 12u * w * h);
    EXPECT_EQ(n.header.frame_id, f.depth->header.frame_id);
    const float* normals = reinterpret_cast<const float*>(n.data.data());
    for (uint32_t v = 0; v < h; ++v)
      for (uint32_t u = 0; u < w; ++u) {
        const size_t p = size_t(v) * w + u;
        const float* q = normals + 3 * p;
        const bool surface = ids[p] != 0 && std::isfinite(depth[p]);
        ASSERT_EQ(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]), surface)
            << "frame " << stamp << " pixel " << u << "," << v;
        if (!surface) continue;
        ++normal_pixels;
        ASSERT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), 1.0, 1e-5);
        ASSERT_LE(q[0] * (u - cx) / fx + q[1] * (v - cy) / fy + q[2], 0.0) << "normal facing away at " << u << "," << v;
      }

    const sensor_msgs::PointCloud2& c = *clouds_.at(stamp);
    const sensor_msgs::Image& semantic = *images_[kSemantic].at(stamp);
    const sensor_msgs::Image& instances = *images_[kInstances].at(stamp);
    ASSERT_EQ(c.fields.size(), 6u);
    const char* names[] = {"x", "y", "z", "rgb", "label", "instance"};
    for (size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(c.fields[i].name, names[i]);
      EXPECT_EQ(c.fields[i].offset, 4 * i);
      EXPECT_EQ(c.fields[i].datatype, i < 4 ? sensor_msgs::PointField::FLOAT32 : sensor_msgs::PointField::UINT32);
      EXPECT_EQ(c.fields[i].count, 1u);
    }
    ASSERT_EQ(c.point_step, 24u);
    ASSERT_EQ(c.width, (w + decimation - 1) / decimation);
    ASSERT_EQ(c.height, (h + decimation - 1) / decimation);
    ASSERT_EQ(c.row_step, 24 * c.width);
    ASSERT_EQ(c.data.size(), size_t(c.row_step) * c.height);
    EXPECT_FALSE(c.is_dense);
    EXPECT_EQ(c.header.frame_id, f.depth->header.frame_id);
    for (uint32_t r = 0; r < c.height; ++r)
      for (uint32_t k = 0; k < c.width; ++k) {
        const size_t o = (size_t(r) * c.width + k) * 24, u = k * decimation, v = r * decimation, p = v * w + u;
        const float x = at<float>(c.data, o), y = at<float>(c.data, o + 4), z = at<float>(c.data, o + 8);
        const uint32_t rgb = at<uint32_t>(c.data, o + 12);
        const uint8_t* col = f.color->data.data() + 3 * p;
        ASSERT_EQ(rgb, (uint32_t(col[0]) << 16) | (uint32_t(col[1]) << 8) | col[2]);
        ASSERT_EQ(at<uint32_t>(c.data, o + 16), semantic.data[p]);
        ASSERT_EQ(at<uint32_t>(c.data, o + 20), uint32_t(std::max(at<int32_t>(instances.data, 4 * p), 0)));
        if (!std::isfinite(depth[p])) {
          ASSERT_TRUE(std::isnan(x) && std::isnan(y) && std::isnan(z));
          continue;
        }
        ++points;
        ASSERT_EQ(z, depth[p]);
        ASSERT_NEAR(x, (u - cx) / fx * z, 1e-5 * z);
        ASSERT_NEAR(y, (v - cy) / fy * z, 1e-5 * z);
      }
  }
  EXPECT_GT(normal_pixels, 10000u);
  EXPECT_GT(points, 2000u);

  // Nobody listens any more: both nodes let their inputs go.
  lock.unlock();  // the callbacks take it: a subscriber's shutdown waits for them
  subs.clear();
  auto released = [&] {
    return pubs["/capture/primitive_ids"].getNumSubscribers() == 0 &&
           pubs["/capture/color/camera_info"].getNumSubscribers() == 0;
  };
  EXPECT_TRUE(viper::test::waitFor(released, deadline)) << "the nodes still read their inputs without subscribers";
}

}  // namespace

int main(int argc, char** argv) { return viper::test::runTester(argc, argv, "geometry_tester"); }
