// The plan of a dataset: its sequences, each with its split, weather condition, ego mode, seed,
// length and image size. `generate --write-plan PRESET` writes one; `generate --plan` generates
// the sequences of a plan, all or a shard of them. Seeds belong to sequences, never to workers, so a
// plan gives the same files whatever the number of shards (docs/dataset_generation.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// One sequence of a plan.
struct PlannedSequence {
  std::string id;         ///< sequence folder name, e.g. "001" (no '/', no '_')
  std::string split;      ///< train, val or test
  std::string condition;  ///< day, sunset, rain, snow or night
  std::string ego;        ///< drive, ride or walk
  uint32_t seed = 1;      ///< the world's town, traffic and people seed
  uint32_t frames = 0;
  uint32_t width = 1920, height = 1080;
};

struct DatasetPlan {
  std::string name;  ///< the preset it came from, or the user's
  double fps = 15.0;
  std::vector<PlannedSequence> sequences;

  uint64_t totalFrames() const;
};

/// The presets: `viper` (VIPER's composition: 184 sequences, 77/47/60 over train/val/test, about
/// 254K frames at 1920x1080 and 15 fps, the five conditions in turn within every split, ego modes
/// mixed), `small` (15 sequences of 200 frames at 1280x720) and `tiny` (3 sequences of 10 frames at
/// 320x180, for tests and a first look). Throws std::invalid_argument for another name.
DatasetPlan presetPlan(const std::string& name);

/// Writes / reads a plan as YAML. read throws std::runtime_error naming the file and the sequence
/// that is wrong (unknown split, condition or ego mode, no frames, a repeated split/id).
void writePlan(const std::string& path, const DatasetPlan& plan);
DatasetPlan readPlan(const std::string& path);

/// The sequences of shard `index` of `count` (every count-th, starting at index), in plan order.
std::vector<PlannedSequence> shardOf(const DatasetPlan& plan, uint32_t index, uint32_t count);

}  // namespace viper::dataset
