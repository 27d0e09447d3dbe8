#include "viper/dataset/dataset_plan.h"

#include "plan_city.h"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <stdexcept>

namespace viper::dataset {
namespace {

const std::vector<std::string> kConditions = {"day", "sunset", "rain", "snow", "night"};
const std::vector<std::string> kEgo = {"drive", "ride", "walk"};

bool oneOf(const std::string& v, const std::vector<std::string>& options) {
  for (const std::string& o : options)
    if (o == v) return true;
  return false;
}

// `per_split[s]` sequences of `frames` each for the splits train, val, test: conditions in turn
// within each split (balanced), ego modes in turn over the whole plan, seed = sequence number; the
// splits are strips of one city (city seed 1), `widths` x `rows` intersections each.
DatasetPlan compose(const std::string& name, const std::vector<uint32_t>& per_split, uint32_t frames, uint32_t width,
                    uint32_t height, const std::vector<int>& widths, int rows) {
  DatasetPlan plan;
  plan.name = name;
  plan.city = stripCity(1, widths, rows);
  const char* splits[] = {"train", "val", "test"};
  uint32_t number = 0;
  for (size_t s = 0; s < 3; ++s)
    for (uint32_t i = 0; i < per_split[s]; ++i) {
      PlannedSequence q;
      ++number;
      char id[8];
      std::snprintf(id, sizeof id, "%03u", number);
      q.id = id;
      q.split = splits[s];
      q.condition = kConditions[(i + s) % kConditions.size()];  // balanced in every split
      q.ego = kEgo[(number - 1) % kEgo.size()];
      q.seed = number;
      q.frames = frames;
      q.width = width;
      q.height = height;
      plan.sequences.push_back(q);
    }
  return plan;
}

}  // namespace

const CityRegion& DatasetPlan::regionOf(const PlannedSequence& s) const {
  if (!city) throw std::logic_error("plan " + name + " has no city");
  return city->regions.at(s.split).at(s.region);
}

uint64_t DatasetPlan::totalFrames() const {
  uint64_t n = 0;
  for (const PlannedSequence& s : sequences) n += s.frames;
  return n;
}

DatasetPlan presetPlan(const std::string& name) {
  // VIPER: 254,064 frames in 184 sequences (77 / 47 / 60): 1,381 frames a sequence on average.
  // Routes of about 1 km (15 blocks) need at least 4 x 4 intersections; the strips are wider so that
  // the routes of a split spread over it.
  if (name == "viper") return compose(name, {77, 47, 60}, 1381, 1920, 1080, {16, 10, 12}, 12);
  if (name == "small") return compose(name, {5, 5, 5}, 200, 1280, 720, {6, 6, 6}, 6);
  if (name == "tiny") return compose(name, {1, 1, 1}, 10, 320, 180, {5, 5, 5}, 5);
  throw std::invalid_argument("unknown preset '" + name + "' (viper, small or tiny)");
}

void writePlan(const std::string& path, const DatasetPlan& plan) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << plan.name << YAML::Key << "fps" << YAML::Value
      << plan.fps << YAML::Key << "sequences" << YAML::Value << YAML::BeginSeq;
  for (const PlannedSequence& s : plan.sequences) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << YAML::DoubleQuoted << s.id
        << YAML::Key << "split" << YAML::Value << s.split << YAML::Key << "condition" << YAML::Value << s.condition
        << YAML::Key << "ego" << YAML::Value << s.ego << YAML::Key << "seed" << YAML::Value << s.seed << YAML::Key
        << "frames" << YAML::Value << s.frames << YAML::Key << "width" << YAML::Value << s.width << YAML::Key
        << "height" << YAML::Value << s.height;
    if (plan.city) out << YAML::Key << "region" << YAML::Value << s.region;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (plan.city) emitCity(out, *plan.city);
  out << YAML::EndMap;
  std::ofstream file(path);
  file << "# A dataset plan (rosrun viper generate --plan THIS --out ROOT); docs/dataset_generation.md\n"
       << out.c_str() << "\n";
  if (!file) throw std::runtime_error("cannot write plan " + path);
}

DatasetPlan readPlan(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& e) {
    throw std::runtime_error("plan " + path + ": " + e.what());
  }
  DatasetPlan plan;
  plan.name = root["name"] ? root["name"].as<std::string>() : path;
  plan.fps = root["fps"] ? root["fps"].as<double>() : 15.0;
  if (!root["sequences"] || !root["sequences"].IsSequence() || root["sequences"].size() == 0)
    throw std::runtime_error("plan " + path + ": no 'sequences' list");
  if (root["city"]) plan.city = readCity(root["city"], "plan " + path);
  std::set<std::string> seen;
  size_t index = 0;
  for (const YAML::Node& n : root["sequences"]) {
    const std::string where = "plan " + path + ", sequence " + std::to_string(index++);
    PlannedSequence s;
    try {
      s.id = n["id"].as<std::string>();
      s.split = n["split"].as<std::string>();
      s.condition = n["condition"] ? n["condition"].as<std::string>() : "day";
      s.ego = n["ego"] ? n["ego"].as<std::string>() : "drive";
      s.seed = n["seed"] ? n["seed"].as<uint32_t>() : 1;
      s.frames = n["frames"].as<uint32_t>();
      s.width = n["width"] ? n["width"].as<uint32_t>() : 1920;
      s.height = n["height"] ? n["height"].as<uint32_t>() : 1080;
      s.region = n["region"] ? n["region"].as<uint32_t>() : 0;
    } catch (const std::exception& e) {
      throw std::runtime_error(where + ": " + e.what() + " (id, split and frames are required)");
    }
    if (!oneOf(s.split, {"train", "val", "test"})) throw std::runtime_error(where + ": split '" + s.split + "'");
    if (!oneOf(s.condition, kConditions)) throw std::runtime_error(where + ": condition '" + s.condition + "'");
    if (!oneOf(s.ego, kEgo)) throw std::runtime_error(where + ": ego mode '" + s.ego + "'");
    if (s.frames == 0) throw std::runtime_error(where + ": no frames");
    if (s.id.empty() || s.id.find_first_of("/_") != std::string::npos)
      throw std::runtime_error(where + ": id '" + s.id + "' (not empty, no '/' or '_')");
    if (plan.city && (!plan.city->regions.count(s.split) || s.region >= plan.city->regions.at(s.split).size()))
      throw std::runtime_error(where + ": region " + std::to_string(s.region) + " of " + s.split +
                               " (the city has " + std::to_string(plan.city->regions.count(s.split)
                               ? plan.city->regions.at(s.split).size() : 0) + ")");
    if (!seen.insert(s.split + "/" + s.id).second) throw std::runtime_error(where + ": " + s.split + "/" + s.id + " twice");
    plan.sequences.push_back(s);
  }
  return plan;
}

std::vector<PlannedSequence> shardOf(const DatasetPlan& plan, uint32_t index, uint32_t count) {
  if (count == 0 || index >= count)
    throw std::invalid_argument("shard " + std::to_string(index) + " of " + std::to_string(count));
  std::vector<PlannedSequence> out;
  for (size_t i = index; i < plan.sequences.size(); i += count) out.push_back(plan.sequences[i]);
  return out;
}

}  // namespace viper::dataset
