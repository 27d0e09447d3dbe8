// The segmentation baseline's core (include/viper/baselines/segmentation_model.h): the committed
// networks on held-out frames of the world (the test region of the city, generated at build time
// from test/evaluation/data/segmentation_test_plan.yaml), against the majority-class predictor;
// the instance baseline on hand-made segmentations; what the model refuses.
#include "viper/baselines/segmentation_model.h"
#include "viper/dataset/viper_sequence.h"
#include "viper/evaluation/semantic_metrics.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <set>

namespace viper {
namespace {

struct HeldOutFrame {
  cv::Mat rgb;  // CV_8UC3
  cv::Mat cls;  // CV_8UC1 class ids
};

/// The held-out frames of the given sequences (test/evaluation/data/segmentation_test_plan.yaml:
/// 001 day, 002 rain, 003 night; empty: all).
std::vector<HeldOutFrame> heldOutFrames(const std::set<std::string>& sequences = {}) {
  std::vector<HeldOutFrame> out;
  for (const std::string& seq : dataset::listViperSequences(VIPER_SEGMENTATION_TEST_LAYOUT, "test")) {
    if (!sequences.empty() && !sequences.count(seq)) continue;
    const dataset::ViperSequenceFiles files = dataset::scanViperSequence(VIPER_SEGMENTATION_TEST_LAYOUT, "test", seq);
    for (const auto& [frame, path] : files.files.at(dataset::ViperModality::kImg)) {
      std::vector<std::string> problems;
      const dataset::ViperFrame f = dataset::readViperFrame(
          files, frame, {}, {dataset::ViperModality::kImg, dataset::ViperModality::kCls}, problems);
      if (!f.img || !f.cls) {
        ADD_FAILURE() << path << ": no img or cls" << (problems.empty() ? "" : ": " + problems[0]);
        continue;
      }
      HeldOutFrame h;
      h.rgb = cv::Mat(int(f.height), int(f.width), CV_8UC3, const_cast<uint8_t*>(f.img->data.data())).clone();
      h.cls = cv::Mat(int(f.height), int(f.width), CV_8UC1, const_cast<uint8_t*>(f.cls->data.data())).clone();
      out.push_back(h);
    }
  }
  return out;
}

SegmentationModel committedModel(const std::string& name) {
  return SegmentationModel(std::string(VIPER_MODELS_DIR) + "/" + name, ClassTable::load(VIPER_CLASSES_CSV),
                           cv::Size(256, 144));
}

/// Mean IoU (cityscapesScripts) and pixel accuracy on the scored pixels, in %, of a network and of
/// the trivial predictor: every pixel the class most frequent in the frames' ground truth.
struct Scores {
  double miou = 0, accuracy = 0, trivial_miou = 0, trivial_accuracy = 0;
};

Scores score(SegmentationModel& model, const std::vector<HeldOutFrame>& frames, const std::string& what) {
  const ClassTable classes = ClassTable::load(VIPER_CLASSES_CSV);
  const std::vector<bool> scored = classes.semanticEvalMask();
  std::vector<uint64_t> counts(256, 0);
  for (const HeldOutFrame& f : frames)
    for (auto it = f.cls.begin<uint8_t>(); it != f.cls.end<uint8_t>(); ++it) ++counts[*it];
  int majority = 0;
  for (int c = 0; c < int(scored.size()); ++c)
    if (scored[c] && counts[c] > counts[majority]) majority = c;

  SemanticConfusion ours(scored), trivial(scored);
  uint64_t correct = 0, correct_trivial = 0, total = 0;
  for (const HeldOutFrame& f : frames) {
    const Segmentation s = model.segment(f.rgb);
    EXPECT_EQ(s.class_ids.size(), f.rgb.size());
    EXPECT_EQ(s.class_ids.type(), CV_8UC1);
    EXPECT_EQ(s.confidence.type(), CV_32FC1);
    std::set<int> ids;
    for (int y = 0; y < f.rgb.rows; ++y)
      for (int x = 0; x < f.rgb.cols; ++x) {
        const int id = s.class_ids.at<uint8_t>(y, x), truth = f.cls.at<uint8_t>(y, x);
        ids.insert(id);
        const float p = s.confidence.at<float>(y, x);
        if (!(p > 0.0f && p <= 1.0f)) ADD_FAILURE() << "confidence " << p << " at " << x << "," << y;
        if (truth < int(scored.size()) && scored[truth]) {
          ++total;
          correct += id == truth;
          correct_trivial += majority == truth;
        }
      }
    for (int id : ids) EXPECT_TRUE(classes.at(id).train_id != 255) << "class id " << id << " is not trained on";
    const cv::Mat all_majority(f.cls.size(), CV_8UC1, cv::Scalar(majority));
    ours.add(f.cls.data, s.class_ids.data, f.cls.total());
    trivial.add(f.cls.data, all_majority.data, f.cls.total());
  }
  const Scores r{100 * ours.meanIou(), 100.0 * correct / total, 100 * trivial.meanIou(), 100.0 * correct_trivial / total};
  std::cout << what << " on " << frames.size() << " held-out frames: mean IoU " << r.miou << " %, pixel accuracy "
            << r.accuracy << " %; every pixel " << classes.at(majority).name << ": mean IoU " << r.trivial_miou
            << " %, pixel accuracy " << r.trivial_accuracy << " %\n";
  return r;
}

// Each network on frames of the conditions it was trained on, against the trivial predictor.
TEST(CommittedModels, BeatTheMajorityClassOnHeldOutFrames) {
  SegmentationModel all = committedModel("segmentation_all.onnx");
  EXPECT_EQ(all.outputClasses(), 23);
  const std::vector<HeldOutFrame> frames = heldOutFrames();
  ASSERT_EQ(frames.size(), 18u) << VIPER_SEGMENTATION_TEST_LAYOUT;
  const Scores a = score(all, frames, "segmentation_all (day, rain, night)");
  EXPECT_GT(a.miou, a.trivial_miou + 20.0);
  EXPECT_GT(a.accuracy, a.trivial_accuracy + 25.0);

  SegmentationModel day_sunset = committedModel("segmentation_day_sunset.onnx");
  const Scores d = score(day_sunset, heldOutFrames({"001"}), "segmentation_day_sunset (day)");
  EXPECT_GT(d.miou, d.trivial_miou + 20.0);
  EXPECT_GT(d.accuracy, d.trivial_accuracy + 25.0);
}

// What Table 1 shows (docs/baselines.md): at night the network that never saw night does worse than
// the one trained on every condition.
TEST(CommittedModels, DaySunsetNetworkFallsBehindAtNight) {
  SegmentationModel all = committedModel("segmentation_all.onnx");
  SegmentationModel day_sunset = committedModel("segmentation_day_sunset.onnx");
  const std::vector<HeldOutFrame> night = heldOutFrames({"003"});
  ASSERT_EQ(night.size(), 6u);
  const Scores a = score(all, night, "segmentation_all (night)");
  const Scores d = score(day_sunset, night, "segmentation_day_sunset (night)");
  EXPECT_GT(a.miou, d.miou + 5.0);
  EXPECT_GT(a.accuracy, d.accuracy + 10.0);
}

class CommittedModel : public ::testing::TestWithParam<const char*> {};

// The instances of the network's output: regions of its instance classes, each of one class.
TEST_P(CommittedModel, InstancesLieOnTheirPredictedClass) {
  SegmentationModel model = committedModel(GetParam());
  const std::vector<bool> instance_class = ClassTable::load(VIPER_CLASSES_CSV).instanceEvalMask();
  size_t instances = 0;
  for (const HeldOutFrame& f : heldOutFrames()) {
    const Segmentation s = model.segment(f.rgb);
    cv::Mat covered(f.rgb.size(), CV_8UC1, cv::Scalar(0));
    for (const InstanceSegment& inst : instancesFromSegmentation(s, instance_class, 10)) {
      ++instances;
      EXPECT_TRUE(instance_class.at(inst.class_id));
      EXPECT_GE(inst.pixels, 10);
      EXPECT_EQ(cv::countNonZero(inst.mask), inst.pixels);
      const cv::Mat of_class = s.class_ids(inst.box) == inst.class_id;
      EXPECT_EQ(cv::countNonZero(inst.mask & ~of_class), 0) << "a mask pixel of another class";
      EXPECT_EQ(cv::countNonZero(inst.mask & covered(inst.box)), 0) << "two instances share a pixel";
      covered(inst.box).setTo(255, inst.mask);
      EXPECT_GT(inst.score, 0.0f);
      EXPECT_LE(inst.score, 1.0f);
    }
  }
  EXPECT_GT(instances, 0u) << "no instance predicted on any held-out frame";
}

INSTANTIATE_TEST_SUITE_P(Models, CommittedModel,
                         ::testing::Values("segmentation_all.onnx", "segmentation_day_sunset.onnx"));

TEST(SegmentationModel, ResizesToTheNetworkAndBack) {
  SegmentationModel model = committedModel("segmentation_all.onnx");
  const std::vector<HeldOutFrame> frames = heldOutFrames({"001"});
  ASSERT_FALSE(frames.empty());
  cv::Mat big;
  cv::resize(frames[0].rgb, big, cv::Size(512, 288), 0, 0, cv::INTER_LINEAR);
  const Segmentation small = model.segment(frames[0].rgb), large = model.segment(big);
  ASSERT_EQ(large.class_ids.size(), cv::Size(512, 288));
  cv::Mat expected;
  cv::resize(small.class_ids, expected, large.class_ids.size(), 0, 0, cv::INTER_NEAREST);
  const double agree = 1.0 - cv::countNonZero(expected != large.class_ids) / double(expected.total());
  std::cout << "512x288 against 256x144 upsampled: " << 100 * agree << " % of pixels agree\n";
  EXPECT_GT(agree, 0.9);
}

Segmentation handMade(const cv::Mat& ids) {
  Segmentation s{ids.clone(), cv::Mat(ids.size(), CV_32FC1)};
  for (int y = 0; y < ids.rows; ++y)
    for (int x = 0; x < ids.cols; ++x) s.confidence.at<float>(y, x) = 0.01f * float(x + 1);
  return s;
}

TEST(InstancesFromSegmentation, ConnectedRegionsOfInstanceClassesScoredByTheirMeanConfidence) {
  const ClassTable classes = ClassTable::load(VIPER_CLASSES_CSV);
  const int car = classes.idOf("car"), person = classes.idOf("person"), road = classes.idOf("road");
  cv::Mat ids(6, 10, CV_8UC1, cv::Scalar(road));
  ids(cv::Rect(0, 0, 2, 2)).setTo(car);  // two car squares touching at a corner: one region (8-connected)
  ids(cv::Rect(2, 2, 2, 2)).setTo(car);
  ids(cv::Rect(7, 0, 3, 1)).setTo(car);  // another car, apart
  ids(cv::Rect(6, 4, 2, 2)).setTo(person);
  ids.at<uint8_t>(5, 0) = uint8_t(person);  // 1 px: under the minimum
  const std::vector<InstanceSegment> out = instancesFromSegmentation(handMade(ids), classes.instanceEvalMask(), 2);
  ASSERT_EQ(out.size(), 3u);
  // Person (20) before car (24): by class, then region order.
  EXPECT_EQ(out[0].class_id, person);
  EXPECT_EQ(out[0].box, cv::Rect(6, 4, 2, 2));
  EXPECT_EQ(out[0].pixels, 4);
  EXPECT_NEAR(out[0].score, 0.075, 1e-6);  // columns 6 and 7: 0.07 and 0.08
  EXPECT_EQ(out[1].class_id, car);
  EXPECT_EQ(out[1].box, cv::Rect(0, 0, 4, 4));
  EXPECT_EQ(out[1].pixels, 8);
  EXPECT_EQ(cv::countNonZero(out[1].mask), 8);
  EXPECT_EQ(out[1].mask.at<uint8_t>(0, 3), 0);
  EXPECT_EQ(out[1].mask.at<uint8_t>(3, 3), 255);
  EXPECT_NEAR(out[1].score, 0.025, 1e-6);  // columns 0, 1, 2, 3 twice each
  EXPECT_EQ(out[2].class_id, car);
  EXPECT_EQ(out[2].box, cv::Rect(7, 0, 3, 1));
  EXPECT_NEAR(out[2].score, 0.09, 1e-6);
  // Road is no instance class; nothing of it comes out.
  EXPECT_TRUE(instancesFromSegmentation(handMade(cv::Mat(4, 4, CV_8UC1, cv::Scalar(road))),
                                        classes.instanceEvalMask(), 1).empty());
}

TEST(SegmentationModel, RefusesWhatItCannotUse) {
  const ClassTable classes = ClassTable::load(VIPER_CLASSES_CSV);
  const std::string model = std::string(VIPER_MODELS_DIR) + "/segmentation_all.onnx";
  try {
    SegmentationModel missing("/nonexistent/model.onnx", classes, cv::Size(256, 144));
    ADD_FAILURE() << "a missing model loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/model.onnx"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SegmentationModel(model, classes, cv::Size(250, 144)), std::runtime_error);

  // A class table with one trained class fewer than the network's outputs.
  const std::filesystem::path csv = std::filesystem::temp_directory_path() / "viper_classes_22.csv";
  {
    std::ifstream in(VIPER_CLASSES_CSV);
    std::ofstream out(csv);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("31,boat", 0) == 0) continue;
      if (line.rfind("27,truck", 0) == 0) line = "27,truck,0,0,70,1,255,1";
      out << line << "\n";
    }
    out << "31,boat,50,0,90,0,255,0\n";
  }
  try {
    SegmentationModel fewer(model, ClassTable::load(csv.string()), cv::Size(256, 144));
    ADD_FAILURE() << "a class table of 22 trained classes took a network of 23";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("23 channels"), std::string::npos) << e.what();
  }
  std::filesystem::remove(csv);

  SegmentationModel ok(model, classes, cv::Size(256, 144));
  EXPECT_THROW(ok.segment(cv::Mat(144, 256, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(ok.segment(cv::Mat()), std::invalid_argument);
}

}  // namespace
}  // namespace viper
