// The plan of a dataset: its sequences, each with its split, weather condition, ego mode, seed,
// length and image size, and the city they are parts of: each split's routes stay inside its own
// regions of one city, so train, val and test are geographically disjoint. `generate --write-plan
// PRESET` writes one; `generate --plan` generates the sequences of a plan, all or a shard of them.
// Seeds belong to sequences, never to workers, so a plan gives the same files whatever the number of
// shards (docs/dataset_generation.md).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace viper::dataset {

/// One sequence of a plan.
struct PlannedSequence {
  std::string id;         ///< sequence folder name, e.g. "001" (no '/', no '_')
  std::string split;      ///< train, val or test
  std::string condition;  ///< day, sunset, rain, snow or night
  std::string ego;        ///< drive, ride or walk
  uint32_t seed = 1;      ///< the world's route, traffic and people seed (and town, without a city)
  uint32_t frames = 0;
  uint32_t width = 1920, height = 1080;
  uint32_t region = 0;    ///< with a city: which of its split's regions the route stays in
};

/// A rectangle of a city's intersections (the world's --region: global indices, bounds inclusive;
/// intersections are RoadDims::kBlock = 72 m apart).
struct CityRegion {
  int i0 = 0, j0 = 0, i1 = 0, j1 = 0;

  /// "I0,J0,I1,J1"
  std::string text() const;
};

/// The one city of a plan: the world's --city-seed (static scenery and light phases), its size in
/// intersections, and the regions of every split.
struct PlanCity {
  uint32_t seed = 1;
  int size_i = 0, size_j = 0;  ///< regions lie in [0, size_i) x [0, size_j)
  std::map<std::string, std::vector<CityRegion>> regions;  ///< split -> its regions

  /// Smallest difference of intersection index between regions of different splits: with 2, one
  /// line of intersections separates them and their roads are 2 blocks (144 m) apart.
  static constexpr int kSplitGap = 2;
};

struct DatasetPlan {
  std::string name;  ///< the preset it came from, or the user's
  double fps = 15.0;
  std::vector<PlannedSequence> sequences;
  std::optional<PlanCity> city;  ///< none: every sequence is a town of its own (plans before cities)

  uint64_t totalFrames() const;
  /// The region a sequence's route stays in (needs a city).
  const CityRegion& regionOf(const PlannedSequence& sequence) const;
};

/// The presets: `viper` (VIPER's composition: 184 sequences, 77/47/60 over train/val/test, about
/// 254K frames at 1920x1080 and 15 fps, the five conditions in turn within every split, ego modes
/// mixed), `small` (15 sequences of 200 frames at 1280x720) and `tiny` (3 sequences of 10 frames at
/// 320x180, for tests and a first look). Each is one city cut into three strips along x, train,
/// val and test, kSplitGap apart (viper 40 x 12 intersections, small 20 x 6, tiny 17 x 5). Throws
/// std::invalid_argument for another name.
DatasetPlan presetPlan(const std::string& name);

/// Writes / reads a plan as YAML. read throws std::runtime_error naming the file and the sequence
/// that is wrong (unknown split, condition or ego mode, no frames, a repeated split/id, a region
/// its split does not have) or the city's regions that are (out of the city, corners out of order,
/// splits closer than kSplitGap, a split with sequences but no region).
void writePlan(const std::string& path, const DatasetPlan& plan);
DatasetPlan readPlan(const std::string& path);

/// The sequences of shard `index` of `count` (every count-th, starting at index), in plan order.
std::vector<PlannedSequence> shardOf(const DatasetPlan& plan, uint32_t index, uint32_t count);

}  // namespace viper::dataset
