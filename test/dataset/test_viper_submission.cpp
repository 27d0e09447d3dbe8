// viper_submission end to end: the test scene's ground truth made by generate (from the committed
// raw bag), a bag of predictions made from it (the ground truth itself, on the evaluate node's
// prediction topics, with bad messages among them), the real command run on it, and every file of
// the submission read back and compared with the ground truth it came from.
#include "viper/dataset/middlebury_flo.h"
#include "viper/dataset/viper_submission.h"
#include "viper/ros/conversions/flow_conversions.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"

#include "dataset_test_util.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <viper/InstancePredictionArray.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

namespace {

using namespace viper::dataset;
using viper_dataset_test::runCommand;
using viper_dataset_test::TempDir;

// The ground truth of one frame, as generate wrote it into its bag.
struct TruthFrame {
  ros::Time stamp;
  Image8 semantic;
  std::vector<int32_t> ids;
  std::optional<FlowImage> flow;
  Eigen::Isometry3d map_from_body;
};

class SubmissionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    std::string out;
    const std::string gt_root = *dir_ / "gt";
    ASSERT_EQ(runCommand(std::string(VIPER_GENERATE) + " --input " + VIPER_SOURCE_DIR + "/bags/test_scene_raw.bag" +
                             " --labels " + VIPER_SOURCE_DIR + "/config/labels/test_scene_labels.yaml --out " + gt_root +
                             " --split test --seq 001 --outputs layout,bag",
                         out),
              0)
        << out;
    gt_bag_ = gt_root + "/test/bag/001.bag";
    readTruth();
    writePredictions(*dir_ / "predictions.bag");
    output_.clear();
    status_ = runCommand(std::string(VIPER_SUBMISSION) + " --bag " + (*dir_ / "predictions.bag") + " --frames " +
                             gt_bag_ + " --out " + (*dir_ / "submission"),
                         output_);
  }
  // VIPER_SUBMISSION_KEEP=DIR keeps the ground truth and the submission (for
  // scripts/viper_submission_check.sh, docs/evaluate.md).
  static void TearDownTestSuite() {
    if (const char* keep = std::getenv("VIPER_SUBMISSION_KEEP"))
      std::filesystem::copy(dir_->path(), keep, std::filesystem::copy_options::recursive);
    delete dir_;
  }

  static void readTruth() {
    rosbag::Bag bag(gt_bag_);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      if (const auto image = m.instantiate<sensor_msgs::Image>()) {
        TruthFrame& f = truth_[image->header.stamp];
        f.stamp = image->header.stamp;
        std::string problem;
        if (m.getTopic() == "/ground_truth/semantic") problem = viper::imageFromMsg(*image, "mono8", f.semantic);
        if (m.getTopic() == "/ground_truth/instance_ids") problem = viper::int32FromMsg(*image, f.ids);
        if (m.getTopic() == "/ground_truth/flow/forward") problem = viper::flowFromMsg(*image, f.flow.emplace());
        ASSERT_EQ(problem, "") << m.getTopic();
      } else if (const auto odom = m.instantiate<nav_msgs::Odometry>()) {
        if (m.getTopic() == "/ground_truth/odom") truth_[odom->header.stamp].map_from_body = viper::fromPoseMsg(odom->pose.pose);
      }
    }
    ASSERT_EQ(truth_.size(), 20u);
  }

  // Instances of a frame: one per instance id, its mask cut to its box, class from the semantic
  // image, score from the id.
  static viper::InstancePredictionArray instancesOf(const TruthFrame& f) {
    viper::InstancePredictionArray msg;
    msg.header.stamp = f.stamp;
    const uint32_t w = f.semantic.width, h = f.semantic.height;
    std::map<int32_t, std::array<uint32_t, 4>> boxes;  // id -> x0, y0, x1, y1
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x)
        if (const int32_t id = f.ids[y * w + x]; id > 0) {
          auto [it, fresh] = boxes.try_emplace(id, std::array<uint32_t, 4>{x, y, x, y});
          auto& b = it->second;
          b = {std::min(b[0], x), std::min(b[1], y), std::max(b[2], x), std::max(b[3], y)};
        }
    for (const auto& [id, b] : boxes) {
      viper::InstancePrediction& p = msg.instances.emplace_back();
      p.x_offset = b[0], p.y_offset = b[1];
      Image8 mask{b[2] - b[0] + 1, b[3] - b[1] + 1, 1, {}};
      mask.data.resize(mask.pixels());
      for (uint32_t y = b[1]; y <= b[3]; ++y)
        for (uint32_t x = b[0]; x <= b[2]; ++x) {
          if (f.ids[y * w + x] != id) continue;
          mask.data[(y - b[1]) * mask.width + x - b[0]] = 1;
          p.class_id = f.semantic.data[y * w + x];
        }
      p.mask = viper::toImageMsg(mask, msg.header, "mono8");
      p.score = static_cast<float>(id % 97) / 96.0f;
    }
    return msg;
  }

  static void writePredictions(const std::string& path) {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (auto it = truth_.begin(); it != truth_.end(); ++it) {
      const auto& [stamp, f] = *it;
      std_msgs::Header header;
      header.stamp = stamp;
      if (f.flow) {  // stamped with the pair's second image, as opencv_apps does (--flow-stamp second)
        std_msgs::Header second;
        second.stamp = std::next(it)->first;
        bag.write("/perception/flow_second", second.stamp, viper::toFlowMsg(*f.flow, second));
      }
      bag.write("/perception/semantic", stamp, viper::toImageMsg(f.semantic, header, "mono8"));
      bag.write("/perception/instances", stamp, instancesOf(f));
      if (f.flow) bag.write("/perception/flow", stamp, viper::toFlowMsg(*f.flow, header));
      nav_msgs::Odometry odom;
      odom.header = header;
      odom.pose.pose = viper::toPoseMsg(f.map_from_body);
      bag.write("/perception/odom", stamp, odom);
    }
    // Bad ones: a stamp of no frame, a flow of the wrong size, a mask leaving the frame.
    const TruthFrame& first = truth_.begin()->second;
    std_msgs::Header unknown;
    unknown.stamp = ros::Time(1000, 5);
    bag.write("/perception/semantic", unknown.stamp, viper::toImageMsg(first.semantic, unknown, "mono8"));
    FlowImage small{2, 2, std::vector<float>(8, 1.0f)};
    std_msgs::Header second_header;
    second_header.stamp = std::next(truth_.begin())->first;
    bag.write("/perception/flow", second_header.stamp, viper::toFlowMsg(small, second_header));
    viper::InstancePredictionArray outside = instancesOf(first);
    outside.instances.at(0).x_offset = first.semantic.width;
    bag.write("/perception/instances", first.stamp, outside);
  }

  static std::string file(const std::string& task, const std::string& name) {
    return *dir_ / ("submission/" + task + "/" + name);
  }

  static TempDir* dir_;
  static std::string gt_bag_, output_;
  static int status_;
  static std::map<ros::Time, TruthFrame> truth_;
};

TempDir* SubmissionTest::dir_ = nullptr;
std::string SubmissionTest::gt_bag_, SubmissionTest::output_;
int SubmissionTest::status_ = -1;
std::map<ros::Time, TruthFrame> SubmissionTest::truth_;

TEST_F(SubmissionTest, BadMessagesAreNamedAndSkipped) {
  EXPECT_EQ(status_, 1) << output_;
  EXPECT_NE(output_.find("skipping /perception/semantic at stamp 1000.000000005: its stamp is not among the 20 frames"),
            std::string::npos)
      << output_;
  EXPECT_NE(output_.find("skipping /perception/flow at stamp 1.066666667: size 2x2"), std::string::npos) << output_;
  EXPECT_NE(output_.find("skipping /perception/instances at stamp 1.000000000: instance 0 mask"), std::string::npos)
      << output_;
  EXPECT_NE(output_.find("/perception/semantic: 20 written, 1 skipped"), std::string::npos) << output_;
}

TEST_F(SubmissionTest, SemanticPngsAreTheClassIdsNamedLikeTheImages) {
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(*dir_ / "submission/cls")) files += e.is_regular_file();
  EXPECT_EQ(files, truth_.size());
  uint64_t frame = 0;
  for (const auto& [stamp, f] : truth_) {
    const std::string path = file("cls", submissionFrameName(1, frame++) + ".png");
    const Image8 read = readViperClassImage(path);
    EXPECT_EQ(read.channels, 1u) << path;
    EXPECT_EQ(read.data, f.semantic.data) << path;
  }
}

TEST_F(SubmissionTest, InstanceMasksMatchTheCsvAndTheGroundTruth) {
  const std::vector<SubmissionInstanceRow> rows = readInstancesCsv(file("inst", "instances.csv"));
  std::map<std::pair<uint64_t, int>, std::vector<int32_t>> ids_by_class;  // the test's numbering
  uint64_t frame = 0;
  size_t instances = 0;
  for (const auto& [stamp, f] : truth_) {
    for (const viper::InstancePrediction& p : instancesOf(f).instances) {
      const size_t k = std::find(p.mask.data.begin(), p.mask.data.end(), 1) - p.mask.data.begin();
      const int32_t id = f.ids[(p.y_offset + k / p.mask.width) * f.semantic.width + p.x_offset + k % p.mask.width];
      ids_by_class[{frame, p.class_id}].push_back(id);
      ++instances;
    }
    ++frame;
  }
  ASSERT_GT(instances, truth_.size());  // the test scene has several instances a frame
  ASSERT_EQ(rows.size(), instances);
  std::vector<const TruthFrame*> frames;
  for (const auto& [stamp, f] : truth_) frames.push_back(&f);
  for (const SubmissionInstanceRow& r : rows) {
    const std::string name = submissionFrameName(r.sequence_id, r.frame) + "_" + std::to_string(r.class_id) + "_" +
                             std::to_string(r.instance_id) + ".png";
    SCOPED_TRACE(name);
    ASSERT_EQ(r.sequence_id, 1);
    ASSERT_LT(r.frame, frames.size());
    const TruthFrame& f = *frames[r.frame];
    const int32_t id = ids_by_class.at({r.frame, r.class_id}).at(r.instance_id - 1);
    EXPECT_NEAR(r.confidence, (id % 97) / 96.0, 1e-7);
    const Image8 mask = readViperClassImage(file("inst", name));
    ASSERT_EQ(mask.data.size(), f.ids.size());
    size_t wrong = 0;
    for (size_t i = 0; i < f.ids.size(); ++i) wrong += (mask.data[i] != 0) != (f.ids[i] == id);
    EXPECT_EQ(wrong, 0u);
  }
}

TEST_F(SubmissionTest, FlowFilesHoldTheFlowOfEachPair) {
  uint64_t frame = 0, files = 0;
  for (const auto& [stamp, f] : truth_) {
    const std::string path = file("flow", submissionFrameName(1, frame++) + ".flo");
    ASSERT_EQ(std::filesystem::exists(path), f.flow.has_value()) << path;
    if (!f.flow) continue;
    ++files;
    const FlowImage read = readMiddleburyFlo(path);
    ASSERT_EQ(read.uv.size(), f.flow->uv.size()) << path;
    for (size_t i = 0; i < read.uv.size(); ++i)
      ASSERT_TRUE(read.uv[i] == f.flow->uv[i] || (std::isnan(read.uv[i]) && std::isnan(f.flow->uv[i])))
          << path << " value " << i;
  }
  EXPECT_EQ(files, truth_.size() - 1);
}

TEST_F(SubmissionTest, FlowStampedWithTheSecondImageNamesTheFirst) {
  const std::string out = *dir_ / "flow_second";
  std::string output;
  ASSERT_EQ(runCommand(std::string(VIPER_SUBMISSION) + " --bag " + (*dir_ / "predictions.bag") + " --frames " + gt_bag_ +
                           " --out " + out + " --flow /perception/flow_second --flow-stamp second" +
                           " --semantic /none --instances /none --odom /none",
                       output),
            0)
      << output;
  EXPECT_FALSE(std::filesystem::exists(out + "/cls"));
  for (uint64_t frame = 0; frame + 1 < truth_.size(); ++frame) {
    const std::string name = submissionFrameName(1, frame) + ".flo";
    EXPECT_EQ(viper_dataset_test::readBytes(out + "/flow/" + name), viper_dataset_test::readBytes(file("flow", name)))
        << name;
  }
  EXPECT_FALSE(std::filesystem::exists(out + "/flow/" + submissionFrameName(1, truth_.size() - 1) + ".flo"));
}

TEST_F(SubmissionTest, OdometryIsTheCameraInKittiAxesRelativeToItsFirstPose) {
  const std::vector<SubmissionPose> poses = readSubmissionOdometry(file("odometry", "001.txt"));
  ASSERT_EQ(poses.size(), truth_.size());
  // The optical axes in the body frame (x forward, y left, z up): right = -y, down = -z, forward = x.
  Eigen::Matrix3d optical_in_body;
  optical_in_body.col(0) = -Eigen::Vector3d::UnitY();
  optical_in_body.col(1) = -Eigen::Vector3d::UnitZ();
  optical_in_body.col(2) = Eigen::Vector3d::UnitX();
  const auto optical = [&](const Eigen::Isometry3d& body) {
    Eigen::Isometry3d o = body;
    o.linear() = body.linear() * optical_in_body;
    return o;
  };
  const Eigen::Isometry3d first = optical(truth_.begin()->second.map_from_body);
  size_t i = 0;
  double path_m = 0.0;
  for (const auto& [stamp, f] : truth_) {
    const SubmissionPose& p = poses[i++];
    const Eigen::Isometry3d expected = first.inverse() * optical(f.map_from_body);
    EXPECT_NEAR(p.timestamp_s, stamp.toSec(), 5e-5);
    EXPECT_LT((p.position - expected.translation()).norm(), 1e-6) << "pose " << i;
    EXPECT_LT(p.orientation.angularDistance(Eigen::Quaterniond(expected.rotation())), 1e-6) << "pose " << i;
    path_m = p.position.norm();
  }
  EXPECT_GT(path_m, 0.1);  // the camera moves: the comparison above is not of identities
  EXPECT_LT(poses.front().position.norm() + poses.front().orientation.vec().norm(), 1e-9);
}

TEST_F(SubmissionTest, AnotherSequenceKeepsTheRowsOfTheFirst) {
  const std::vector<SubmissionInstanceRow> before = readInstancesCsv(file("inst", "instances.csv"));
  const std::string two = *dir_ / "two_sequences";
  std::filesystem::copy(*dir_ / "submission", two, std::filesystem::copy_options::recursive);
  std::string out;
  EXPECT_EQ(runCommand(std::string(VIPER_SUBMISSION) + " --bag " + (*dir_ / "predictions.bag") + " --frames " +
                           gt_bag_ + " --seq 7 --out " + two,
                       out),
            1)
      << out;
  const std::vector<SubmissionInstanceRow> after = readInstancesCsv(two + "/inst/instances.csv");
  ASSERT_EQ(after.size(), 2 * before.size());
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(after[i].sequence_id, 1);
    EXPECT_EQ(after[before.size() + i].sequence_id, 7);
    EXPECT_EQ(after[before.size() + i].frame, before[i].frame);
  }
  EXPECT_TRUE(std::filesystem::exists(two + "/odometry/007.txt"));
  EXPECT_TRUE(std::filesystem::exists(two + "/odometry/001.txt"));
  EXPECT_TRUE(std::filesystem::exists(two + "/cls/007_00019.png"));
}

}  // namespace
