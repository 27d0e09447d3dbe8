// The statistics of a generated dataset: the tiny plan generated end to end (the world under
// capture) and merged; generate --merge writes statistics.md, the CSVs and the PNGs, and their counts
// agree with the test's own count of the dataset's files: instances as the distinct (class, id)
// pairs of the inst PNGs read with OpenCV, vehicles as the visible vehicle rows of the bb files.
// dataset_statistics computes the same files again.
#include "viper/ground_truth/class_table.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using viper::test::readFile;
using viper::test::run;
using viper::test::tempDir;

// Per split: the sum of count (or of bin * count) over a statistic's CSV rows.
std::map<std::string, uint64_t> sumBySplit(const std::string& csv_path, bool times_bin) {
  std::istringstream in(readFile(csv_path));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "split,condition,bin,count") << csv_path;
  std::map<std::string, uint64_t> sum;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string v; std::getline(fields, v, ',');) f.push_back(v);
    if (f.size() != 4) {
      ADD_FAILURE() << csv_path << ": " << line;
      continue;
    }
    sum[f[0]] += std::stoull(f[3]) * (times_bin ? std::stoull(f[2]) : 1);
  }
  return sum;
}

// What the test finds in the files of one split.
struct Counted {
  uint64_t images = 0, instances = 0, vehicles = 0;
  uint64_t pixels = 0, unlabeled = 0;  // class 0 in the inst files' R channel
};

Counted countSplit(const fs::path& split, const viper::ClassTable& classes) {
  Counted c;
  const std::set<int> vehicles = {classes.idOf("motorcycle"), classes.idOf("car"), classes.idOf("van"),
                                  classes.idOf("bus"), classes.idOf("truck")};
  for (const auto& e : fs::recursive_directory_iterator(split / "inst")) {
    if (e.path().extension() != ".png") continue;
    const cv::Mat bgr = cv::imread(e.path().string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(bgr.empty()) << e.path();
    std::set<uint32_t> instances;
    for (int y = 0; y < bgr.rows; ++y)
      for (int x = 0; x < bgr.cols; ++x) {
        const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);  // B, G, R: class R, id 256 G + B
        ++c.pixels;
        c.unlabeled += p[2] == 0;
        if ((p[1] | p[0]) != 0 && classes.at(p[2]).instance_eval) instances.insert(p[2] << 16 | p[1] << 8 | p[0]);
      }
    ++c.images;
    c.instances += instances.size();
  }
  for (const auto& e : fs::recursive_directory_iterator(split / "bb")) {
    std::istringstream in(readFile(e.path().string()));
    for (std::string line; std::getline(in, line);) {
      std::stringstream fields(line);
      std::string class_id, instance_id, x_min;
      std::getline(fields, class_id, ',');
      std::getline(fields, instance_id, ',');
      std::getline(fields, x_min, ',');
      if (vehicles.count(std::stoi(class_id)) && std::stod(x_min) >= 0) ++c.vehicles;
    }
  }
  return c;
}

TEST(GenerateStatistics, MergeWritesStatisticsThatAgreeWithTheFiles) {
  const std::string dir = tempDir("viper_stats_"), plan = dir + "/tiny.yaml", root = dir + "/root";
  const std::string generate = VIPER_GENERATE, log = " > " + dir + "/log 2>&1";
  ASSERT_EQ(run(generate + " --write-plan tiny --plan " + plan + log), 0);
  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + root + log), 0) << readFile(dir + "/log");
  ASSERT_EQ(run(generate + " --merge --plan " + plan + " --out " + root + log), 0) << readFile(dir + "/log");
  const std::string out = readFile(dir + "/log");
  EXPECT_NE(out.find("statistics 2/3: val/002 (sunset)"), std::string::npos) << "progress names the sequence: " << out;

  const std::string md = readFile(root + "/statistics.md");
  ASSERT_FALSE(md.empty()) << "statistics.md beside manifest.md";
  EXPECT_NE(md.find("30 images (frames with a cls or inst file) in 3 sequences"), std::string::npos) << md;
  EXPECT_NE(md.find("| train / val | train / test | val / test |"), std::string::npos) << md;
  for (const char* name : {"classes_per_image", "instances_per_image", "instances_per_class", "vehicles_by_distance",
                           "pixels_per_class"}) {
    EXPECT_TRUE(fs::exists(root + "/statistics/" + name + ".csv")) << name;
    const cv::Mat png = cv::imread(root + "/statistics/" + name + ".png");
    EXPECT_GT(png.cols, 0) << name << ".png";
    EXPECT_NE(md.find(std::string("](statistics/") + name + ".png)"), std::string::npos) << name;
  }

  const viper::ClassTable classes = viper::ClassTable::load(VIPER_CLASS_TABLE);
  const std::string stats = root + "/statistics/";
  const auto images = sumBySplit(stats + "classes_per_image.csv", false);
  const auto per_image = sumBySplit(stats + "instances_per_image.csv", true);
  const auto per_class = sumBySplit(stats + "instances_per_class.csv", false);
  const auto vehicles = sumBySplit(stats + "vehicles_by_distance.csv", false);
  for (const char* split : {"train", "val", "test"}) {
    const Counted c = countSplit(fs::path(root) / split, classes);
    EXPECT_EQ(c.images, 10u) << split;
    EXPECT_GT(c.instances, 0u) << split << ": the world has objects";
    EXPECT_GT(c.vehicles, 0u) << split << ": the world has traffic";
    EXPECT_EQ(images.at(split), c.images) << split;
    EXPECT_EQ(per_image.at(split), c.instances) << split << ": instances per image, summed";
    EXPECT_EQ(per_class.at(split), c.instances) << split << ": instances per class, summed";
    EXPECT_EQ(vehicles.at(split), c.vehicles) << split;
    // Every sequence is labelled from the world's own oracle of its run (each has meshes of its own).
    EXPECT_LT(c.unlabeled, c.pixels / 100) << split << ": " << c.unlabeled << " of " << c.pixels << " pixels unlabeled";
  }

  // Computed again, with and without the plan.
  std::map<std::string, std::string> before;
  for (const auto& e : fs::directory_iterator(stats)) before[e.path().filename()] = readFile(e.path().string());
  ASSERT_EQ(run(std::string(VIPER_DATASET_STATISTICS) + " --root " + root + " --plan " + plan + log), 0);
  for (const auto& [name, bytes] : before) EXPECT_EQ(readFile(stats + name), bytes) << name << " the same again";
  ASSERT_EQ(run(std::string(VIPER_DATASET_STATISTICS) + " --root " + root + log), 0);
  EXPECT_NE(readFile(stats + "classes_per_image.csv").find("train,unknown,"), std::string::npos)
      << "without a plan the condition is unknown";
  EXPECT_EQ(sumBySplit(stats + "instances_per_class.csv", false), per_class) << "the same counts";
  EXPECT_EQ(run(std::string(VIPER_DATASET_STATISTICS) + " --root " + dir + "/nothing" + log), 2);
  EXPECT_NE(readFile(dir + "/log").find(dir + "/nothing"), std::string::npos) << readFile(dir + "/log");
}

}  // namespace
