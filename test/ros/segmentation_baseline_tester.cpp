// Feeds segmentation_baseline (segmentation_baseline.test) held-out frames of the world (the build's
// test_data/segmentation, day) and bad images, and checks what it promises: per good image a mono8
// semantic image of its size, stamp and frame id, with class ids of trained classes, the same for
// the same pixels in rgb8 and bgr8; per good image an instance array of the same stamp whose masks
// are exactly the connected regions (8-connected, >= ~min_instance_px) of the instance classes of
// that semantic image; bad images dropped without output, with an error on /rosout naming the topic.
#include "tester_main.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/ground_truth/class_table.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>
#include <viper/InstancePredictionArray.h>

#include <functional>
#include <map>
#include <mutex>

namespace {

namespace dataset = viper::dataset;

constexpr char kImageTopic[] = "/camera/image";

sensor_msgs::Image imageMsg(const cv::Mat& rgb, const std::string& encoding, const ros::Time& stamp) {
  sensor_msgs::Image m;
  m.header.stamp = stamp;
  m.header.frame_id = "camera_optical";
  m.width = uint32_t(rgb.cols), m.height = uint32_t(rgb.rows);
  m.encoding = encoding;
  cv::Mat out = rgb;
  if (encoding == "bgr8") cv::cvtColor(rgb, out, cv::COLOR_RGB2BGR);
  m.step = uint32_t(out.cols * out.elemSize());
  m.data.assign(out.data, out.data + out.total() * out.elemSize());
  return m;
}

std::vector<cv::Mat> dayFrames() {
  const dataset::ViperSequenceFiles files = dataset::scanViperSequence(VIPER_SEGMENTATION_TEST_LAYOUT, "test", "001");
  std::vector<cv::Mat> out;
  for (const auto& entry : files.files.at(dataset::ViperModality::kImg)) {
    std::vector<std::string> problems;
    const dataset::ViperFrame f =
        dataset::readViperFrame(files, entry.first, {}, {dataset::ViperModality::kImg}, problems);
    if (f.img) out.push_back(cv::Mat(int(f.height), int(f.width), CV_8UC3, const_cast<uint8_t*>(f.img->data.data())).clone());
  }
  return out;
}

class SegmentationBaselineTest : public ::testing::Test {
 protected:
  std::mutex mutex_;
  std::map<ros::Time, sensor_msgs::Image> semantic_;
  std::map<ros::Time, viper::InstancePredictionArray> instances_;
  std::vector<rosgraph_msgs::Log> logs_;

  template <typename Map>
  size_t count(const Map& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    return m.size();
  }
  bool loggedError(const std::string& a, const std::string& b) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& l : logs_)
      if (l.level >= rosgraph_msgs::Log::ERROR && l.msg.find(a) != std::string::npos && l.msg.find(b) != std::string::npos)
        return true;
    return false;
  }
};

// The instance arrays against the connected regions of the semantic image's instance classes.
void checkInstances(const sensor_msgs::Image& semantic, const viper::InstancePredictionArray& instances,
                    const std::vector<bool>& instance_class, int min_px) {
  const cv::Mat ids(int(semantic.height), int(semantic.width), CV_8UC1, const_cast<uint8_t*>(semantic.data.data()));
  std::map<int, cv::Mat> union_of;  // class -> union of its masks
  std::map<int, int> masks_of;
  for (const viper::InstancePrediction& p : instances.instances) {
    ASSERT_LT(p.class_id, instance_class.size());
    EXPECT_TRUE(instance_class[p.class_id]) << "class " << int(p.class_id) << " has no instances";
    ASSERT_EQ(p.mask.encoding, "mono8");
    ASSERT_LE(p.x_offset + p.mask.width, semantic.width);
    ASSERT_LE(p.y_offset + p.mask.height, semantic.height);
    ASSERT_EQ(p.mask.data.size(), size_t(p.mask.step) * p.mask.height);
    EXPECT_GT(p.score, 0.0f);
    EXPECT_LE(p.score, 1.0f);
    const cv::Rect box(int(p.x_offset), int(p.y_offset), int(p.mask.width), int(p.mask.height));
    const cv::Mat mask = cv::Mat(box.size(), CV_8UC1, const_cast<uint8_t*>(p.mask.data.data()), p.mask.step) != 0;
    EXPECT_GE(cv::countNonZero(mask), min_px);
    EXPECT_EQ(cv::countNonZero(mask & (ids(box) != p.class_id)), 0) << "mask pixels of another class";
    cv::Mat& u = union_of.try_emplace(p.class_id, cv::Mat(ids.size(), CV_8UC1, cv::Scalar(0))).first->second;
    EXPECT_EQ(cv::countNonZero(mask & u(box)), 0) << "two instances of class " << int(p.class_id) << " overlap";
    u(box).setTo(255, mask);
    ++masks_of[p.class_id];
  }
  for (size_t c = 0; c < instance_class.size(); ++c) {
    if (!instance_class[c]) continue;
    cv::Mat labels, stats, centroids, large(ids.size(), CV_8UC1, cv::Scalar(0));
    const int n = cv::connectedComponentsWithStats(ids == int(c), labels, stats, centroids, 8, CV_32S);
    int regions = 0;
    for (int k = 1; k < n; ++k)
      if (stats.at<int>(k, cv::CC_STAT_AREA) >= min_px) ++regions, large.setTo(255, labels == k);
    EXPECT_EQ(masks_of[int(c)], regions) << "class " << c;
    const cv::Mat u = union_of.count(int(c)) ? union_of[int(c)] : cv::Mat(ids.size(), CV_8UC1, cv::Scalar(0));
    EXPECT_EQ(cv::countNonZero(u != large), 0) << "class " << c << ": masks differ from its regions";
  }
}

TEST_F(SegmentationBaselineTest, SegmentsGoodImagesDropsBadOnes) {
  ros::NodeHandle nh, pnh("~");
  int min_px = 10;
  pnh.param("min_instance_px", min_px, min_px);
  const viper::ClassTable classes = viper::ClassTable::load(VIPER_CLASSES_CSV);
  const std::vector<cv::Mat> frames = dayFrames();
  ASSERT_GE(frames.size(), 3u) << VIPER_SEGMENTATION_TEST_LAYOUT;

  ros::Publisher image = nh.advertise<sensor_msgs::Image>(kImageTopic, 20);
  auto semantic = nh.subscribe<sensor_msgs::Image>("/baselines/semantic", 20, [this](const sensor_msgs::Image::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    semantic_[m->header.stamp] = *m;
  });
  auto instances = nh.subscribe<viper::InstancePredictionArray>(
      "/baselines/instances", 20, [this](const viper::InstancePredictionArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex_);
        instances_[m->header.stamp] = *m;
      });
  auto rosout = nh.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::Log::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(*m);
  });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(45);
  auto wait = [&](const std::function<bool()>& ok) {
    while (!ok() && ros::WallTime::now() < deadline) ros::WallDuration(0.01).sleep();
    return ok();
  };
  ASSERT_TRUE(wait([&] {
    return image.getNumSubscribers() >= 1 && semantic.getNumPublishers() >= 1 && instances.getNumPublishers() >= 1 &&
           rosout.getNumPublishers() >= 2;
  })) << "segmentation_baseline did not connect";

  cv::Mat large;
  cv::resize(frames[2], large, cv::Size(512, 288), 0, 0, cv::INTER_LINEAR);
  const ros::Time t0(10.0), t1(10.1), t2(10.2), bad_encoding(10.3), bad_size(10.4), t5(10.5);
  image.publish(imageMsg(frames[0], "rgb8", t0));
  image.publish(imageMsg(frames[0], "bgr8", t1));
  image.publish(imageMsg(large, "rgb8", t2));
  sensor_msgs::Image depth = imageMsg(frames[1], "rgb8", bad_encoding);
  depth.encoding = "32FC1";
  image.publish(depth);
  sensor_msgs::Image truncated = imageMsg(frames[1], "rgb8", bad_size);
  truncated.data.resize(truncated.data.size() / 2);
  image.publish(truncated);
  image.publish(imageMsg(frames[1], "rgb8", t5));

  ASSERT_TRUE(wait([&] { return count(semantic_) >= 4 && count(instances_) >= 4; }))
      << "semantic " << count(semantic_) << ", instances " << count(instances_) << " of 4";
  EXPECT_TRUE(wait([&] { return loggedError(kImageTopic, "dropped"); })) << "no error naming " << kImageTopic;
  std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(semantic_.size(), 4u);
  EXPECT_EQ(instances_.size(), 4u);
  EXPECT_EQ(semantic_.count(bad_encoding) + semantic_.count(bad_size), 0u) << "a bad image was segmented";
  for (const auto& [stamp, size] : std::map<ros::Time, cv::Size>{{t0, frames[0].size()}, {t1, frames[0].size()},
                                                                 {t2, large.size()}, {t5, frames[1].size()}}) {
    SCOPED_TRACE("frame at " + std::to_string(stamp.toSec()));
    ASSERT_TRUE(semantic_.count(stamp) && instances_.count(stamp));
    const sensor_msgs::Image& s = semantic_[stamp];
    EXPECT_EQ(s.header.frame_id, "camera_optical");
    EXPECT_EQ(s.encoding, "mono8");
    ASSERT_EQ(int(s.width), size.width);
    ASSERT_EQ(int(s.height), size.height);
    ASSERT_EQ(s.step, s.width);
    ASSERT_EQ(s.data.size(), size_t(s.width) * s.height);
    std::vector<bool> seen(256, false);
    for (uint8_t id : s.data) seen[id] = true;
    for (int id = 0; id < 256; ++id) {
      if (seen[id]) {
        EXPECT_TRUE(id < int(classes.size()) && classes.at(id).train_id != 255) << "class id " << id;
      }
    }
    checkInstances(s, instances_[stamp], classes.instanceEvalMask(), min_px);
  }
  EXPECT_EQ(semantic_[t0].data, semantic_[t1].data) << "the same pixels as rgb8 and bgr8 segment differently";
  size_t predicted = 0;
  for (const auto& entry : instances_) predicted += entry.second.instances.size();
  EXPECT_GT(predicted, 0u) << "no instance in four frames of a town";
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "segmentation_baseline_tester");
}
