// Geographically disjoint splits (one city, a region per split): every route of the viper preset
// stays in its split's region and no two splits' paths come within one block; the tiny plan,
// generated end to end, keeps the same distance on the camera positions of its ground-truth bags;
// one place of a city has the same scenery in every sequence; the plan's city and the world's
// options are checked with clear errors.
#include "viper/dataset/dataset_plan.h"

#include "../common/process_util.h"
#include "dataset_test_util.h"

#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace {

using viper::dataset::CityRegion;
using viper::dataset::DatasetPlan;
using viper::dataset::PlannedSequence;
using viper::dataset::presetPlan;
using viper::test::readFile;
using viper::test::run;
using viper::test::tempDir;

constexpr double kBlock = 72.0;       // RoadDims::kBlock: intersections this far apart
constexpr double kSidewalk = 11.0;    // RoadDims::kSidewalkOuter: the widest path offset from a road

struct Point {
  double x = 0, y = 0;
};

// What `world --print-route` prints.
struct PrintedRoute {
  std::vector<std::pair<int, int>> intersections;
  double length_m = 0;
  std::vector<Point> path;
};

std::string cityArgs(const DatasetPlan& plan, const PlannedSequence& q) {
  return " --seed " + std::to_string(q.seed) + " --ego " + q.ego + " --city-seed " + std::to_string(plan.city->seed) +
         " --region " + plan.regionOf(q).text();
}

// Runs the world with `args`; its stdout, or "" and a failure when it exits otherwise than 0.
std::string worldOutput(const std::string& args) {
  const std::string out = tempDir("viper_city_") + "/world.out";
  const int code = run(std::string(VIPER_WORLD) + args + " > " + out + " 2>&1");
  EXPECT_EQ(code, 0) << "world" << args << ": " << readFile(out);
  return code == 0 ? readFile(out) : "";
}

PrintedRoute printRoute(const std::string& args) {
  std::istringstream in(worldOutput(" --print-route" + args));
  PrintedRoute r;
  std::string key;
  size_t n = 0;
  char comma = 0;
  while (in >> key) {
    if (key == "path_length_m") {
      in >> r.length_m;
      continue;
    }
    in >> n;
    for (size_t k = 0; k < n; ++k) {
      if (key == "route_intersections") {
        std::pair<int, int> p;
        in >> p.first >> comma >> p.second;
        r.intersections.push_back(p);
      } else {
        Point p;
        in >> p.x >> comma >> p.y;
        r.path.push_back(p);
      }
    }
  }
  return r;
}

// Smallest distance between a point of one split and a point of another; names the pair.
double closestAcrossSplits(const std::map<std::string, std::vector<Point>>& per_split, std::string& pair) {
  double best = 1e18;
  for (const auto& [a, pa] : per_split)
    for (const auto& [b, pb] : per_split) {
      if (a >= b) continue;
      for (const Point& p : pa)
        for (const Point& q : pb) {
          const double d = std::hypot(p.x - q.x, p.y - q.y);
          if (d < best) best = d, pair = a + "/" + b + " near (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ")";
        }
    }
  return best;
}

bool nearRegion(const Point& p, const CityRegion& r, double margin) {
  return p.x >= r.i0 * kBlock - margin && p.x <= r.i1 * kBlock + margin && p.y >= r.j0 * kBlock - margin &&
         p.y <= r.j1 * kBlock + margin;
}

TEST(CitySplits, ViperPresetRoutesStayInTheirRegionsAndSplitsStayApart) {
  const DatasetPlan plan = presetPlan("viper");
  ASSERT_TRUE(plan.city);
  std::map<std::string, std::vector<Point>> per_split;
  std::map<std::string, std::map<std::string, int>> conditions, ego;  // split -> value -> sequences
  for (const PlannedSequence& q : plan.sequences) {
    ++conditions[q.split][q.condition];
    ++ego[q.split][q.ego];
    const PrintedRoute r = printRoute(cityArgs(plan, q));
    const CityRegion& region = plan.regionOf(q);
    ASSERT_EQ(r.intersections.size(), 16u) << q.split << "/" << q.id << ": a route of 1000 m visits 16 intersections";
    EXPECT_GT(r.length_m, 900.0) << q.split << "/" << q.id;
    ASSERT_GT(r.path.size(), r.length_m / 5.0) << q.split << "/" << q.id << ": a point every 5 m";
    for (const auto& [i, j] : r.intersections)
      EXPECT_TRUE(i >= region.i0 && i <= region.i1 && j >= region.j0 && j <= region.j1)
          << q.split << "/" << q.id << ": intersection " << i << "," << j << " outside " << region.text();
    for (const Point& p : r.path)
      EXPECT_TRUE(nearRegion(p, region, kSidewalk))
          << q.split << "/" << q.id << ": path point " << p.x << "," << p.y << " outside " << region.text();
    per_split[q.split].insert(per_split[q.split].end(), r.path.begin(), r.path.end());
  }
  ASSERT_EQ(per_split.size(), 3u);
  std::string pair;
  const double closest = closestAcrossSplits(per_split, pair);
  EXPECT_GT(closest, kBlock) << "the paths of " << pair << " come within one block";
  std::printf("viper preset: closest path points of two splits %.1f m apart (%s)\n", closest, pair.c_str());
  // Balanced as the plan says: in every split each condition and each ego mode, counts within one.
  for (const auto* table : {&conditions, &ego})
    for (const auto& [split, counts] : *table) {
      EXPECT_EQ(counts.size(), table == &conditions ? 5u : 3u) << split;
      int lo = 1 << 30, hi = 0;
      for (const auto& [value, n] : counts) lo = std::min(lo, n), hi = std::max(hi, n);
      EXPECT_LE(hi - lo, 1) << split << ": balanced";
    }
}

// Camera positions (the body's translation in the map frame) of a ground-truth bag's /tf.
std::vector<Point> cameraPositions(const std::string& bag_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<Point> out;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf"))) {
    const auto tf = m.instantiate<tf2_msgs::TFMessage>();
    if (!tf) continue;
    for (const auto& t : tf->transforms) out.push_back({t.transform.translation.x, t.transform.translation.y});
  }
  return out;
}

TEST(CitySplits, TinyPlanCamerasOfDifferentSplitsStayApart) {
  const std::string dir = tempDir("viper_city_"), plan_path = dir + "/tiny.yaml";
  const std::string generate = VIPER_GENERATE;
  ASSERT_EQ(run(generate + " --write-plan tiny --plan " + plan_path + " > /dev/null"), 0);
  const DatasetPlan plan = viper::dataset::readPlan(plan_path);
  ASSERT_TRUE(plan.city);
  ASSERT_EQ(run(generate + " --plan " + plan_path + " --out " + dir + "/tiny > " + dir + "/log 2>&1"), 0)
      << readFile(dir + "/log");
  std::map<std::string, std::vector<Point>> per_split;
  for (const PlannedSequence& q : plan.sequences) {
    const std::vector<Point> cams = cameraPositions(dir + "/tiny/" + q.split + "/bag/" + q.id + ".bag");
    ASSERT_EQ(cams.size(), q.frames) << q.split << "/" << q.id << ": a pose a frame";
    // The cameras are where the world's route is, at the city's coordinates.
    const PrintedRoute r = printRoute(cityArgs(plan, q));
    for (const Point& c : cams) {
      EXPECT_TRUE(nearRegion(c, plan.regionOf(q), kSidewalk)) << q.split << "/" << q.id << ": " << c.x << "," << c.y;
      double to_path = 1e18;
      for (const Point& p : r.path) to_path = std::min(to_path, std::hypot(c.x - p.x, c.y - p.y));
      EXPECT_LT(to_path, 5.0) << q.split << "/" << q.id << ": camera " << c.x << "," << c.y << " off its route";
    }
    per_split[q.split] = cams;
  }
  std::string pair;
  EXPECT_GT(closestAcrossSplits(per_split, pair), kBlock) << "the cameras of " << pair << " come within one block";
}

// Block chunks (name -> content hash) of `world --list-meshes`.
std::map<std::string, std::string> blockMeshes(const std::string& args) {
  std::istringstream in(worldOutput(" --list-meshes" + args));
  std::map<std::string, std::string> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string name, class_id, class_name, vertices, triangles, hash;
    if (fields >> name >> class_id >> class_name >> vertices >> triangles >> hash && name.rfind("block_", 0) == 0)
      out[name] = hash;
  }
  return out;
}

TEST(CitySplits, OnePlaceHasTheSameSceneryInEverySequenceOfACity) {
  const DatasetPlan plan = presetPlan("viper");
  // The first two sequences of the train split whose routes pass the same intersection.
  std::vector<std::set<std::pair<int, int>>> visited;
  const PlannedSequence *a = nullptr, *b = nullptr;
  for (size_t k = 0; k < plan.sequences.size() && !b && plan.sequences[k].split == "train"; ++k) {
    const PrintedRoute r = printRoute(cityArgs(plan, plan.sequences[k]));
    visited.emplace_back(r.intersections.begin(), r.intersections.end());
    for (size_t m = 0; m + 1 < visited.size() && !b; ++m)
      for (const auto& place : visited.back())
        if (visited[m].count(place)) a = &plan.sequences[m], b = &plan.sequences[k];
  }
  ASSERT_TRUE(a && b) << "two train routes that meet";
  const auto first = blockMeshes(cityArgs(plan, *a)), second = blockMeshes(cityArgs(plan, *b));
  DatasetPlan other_city = plan;
  other_city.city->seed += 1;
  const auto other = blockMeshes(cityArgs(other_city, *b));
  size_t shared = 0;
  std::set<std::string> blocks, changed_blocks;
  for (const auto& [name, hash] : first) {
    if (!second.count(name)) continue;
    ++shared;
    EXPECT_EQ(hash, second.at(name)) << name << " differs between seeds " << a->seed << " and " << b->seed;
  }
  for (const auto& [name, hash] : second) {
    const std::string block = name.substr(0, name.rfind('_'));  // block_I_J
    blocks.insert(block);
    if (!other.count(name) || other.at(name) != hash) changed_blocks.insert(block);  // a park has no buildings
  }
  EXPECT_GT(shared, 100u) << "the two towns overlap";
  EXPECT_GT(changed_blocks.size(), blocks.size() / 2) << "another city seed, other blocks";
  std::printf("%zu block meshes in both towns, all equal; another city seed changes %zu of %zu blocks\n", shared,
              changed_blocks.size(), blocks.size());
}

TEST(CitySplits, BadCitiesAreNamed) {
  const std::string log = tempDir("viper_city_") + "/bad.log";
  for (const auto& [args, expected] : std::map<std::string, std::string>{
           {" --region 0,0,5,5", "--region needs --city-seed"},
           {" --city-seed 3", "--city-seed needs --region"},
           {" --city-seed 3 --region 5,0,0,5", "is not I0,J0,I1,J1"},
           {" --city-seed 3 --region 0,0,5", "is not I0,J0,I1,J1"},
           {" --city-seed 3 --region 0,0,3,2", "holds 12 intersections; a route of 1000 m visits 16"}}) {
    EXPECT_EQ(run(std::string(VIPER_WORLD) + " --print-route" + args + " > " + log + " 2>&1"), 2) << args;
    EXPECT_NE(readFile(log).find(expected), std::string::npos) << args << ": " << readFile(log);
  }
  const std::string path = tempDir("viper_city_") + "/city.yaml";
  const std::string sequence = "sequences:\n  - {id: '001', split: train, frames: 3, region: 0}\n";
  for (const auto& [city, expected] : std::map<std::string, std::string>{
           {"city: {seed: 1, size: [9, 4], regions: {train: [[0, 0, 3, 3]], val: [[4, 0, 8, 3]]}}",
            "train[0] 0,0,3,3 and val[0] 4,0,8,3 are fewer than 2 intersections apart"},
           {"city: {seed: 1, size: [9, 4], regions: {train: [[0, 0, 9, 3]]}}", "not a rectangle inside"},
           {"city: {seed: 1, size: [9, 4], regions: {val: [[0, 0, 3, 3]]}}", "region 0 of train"},
           {"city: {seed: 1, regions: {train: [[0, 0, 3, 3]]}}", "city: "}}) {
    std::ofstream(path) << sequence << city << "\n";
    viper_dataset_test::expectErrorNaming([&] { viper::dataset::readPlan(path); }, {expected, path}, city);
  }
  // The presets' cities read back as written.
  const DatasetPlan viper = presetPlan("viper");
  viper::dataset::writePlan(path, viper);
  const DatasetPlan back = viper::dataset::readPlan(path);
  ASSERT_TRUE(back.city);
  EXPECT_EQ(back.city->seed, viper.city->seed);
  EXPECT_EQ(back.city->size_i, viper.city->size_i);
  for (const PlannedSequence& q : viper.sequences) EXPECT_EQ(back.regionOf(q).text(), viper.regionOf(q).text());
}

}  // namespace
