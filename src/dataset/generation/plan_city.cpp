#include "plan_city.h"

#include <algorithm>
#include <stdexcept>

namespace viper::dataset {
namespace {

// Index distance between two rectangles: the larger of the gaps along i and along j (0 when they
// overlap in both).
int gap(const CityRegion& a, const CityRegion& b) {
  const int di = std::max(a.i0 - b.i1, b.i0 - a.i1), dj = std::max(a.j0 - b.j1, b.j0 - a.j1);
  return std::max({di, dj, 0});
}

void checkCity(const PlanCity& city, const std::string& where) {
  if (city.size_i <= 0 || city.size_j <= 0)
    throw std::runtime_error(where + ": city size " + std::to_string(city.size_i) + " x " +
                             std::to_string(city.size_j) + " (both > 0)");
  for (const auto& [split, list] : city.regions) {
    if (split != "train" && split != "val" && split != "test")
      throw std::runtime_error(where + ": city regions of split '" + split + "'");
    if (list.empty()) throw std::runtime_error(where + ": city regions of " + split + ": an empty list");
    for (size_t k = 0; k < list.size(); ++k) {
      const CityRegion& r = list[k];
      if (r.i0 < 0 || r.j0 < 0 || r.i0 > r.i1 || r.j0 > r.j1 || r.i1 >= city.size_i || r.j1 >= city.size_j)
        throw std::runtime_error(where + ": city region " + split + "[" + std::to_string(k) + "] " + r.text() +
                                 " is not a rectangle inside the city's " + std::to_string(city.size_i) + " x " +
                                 std::to_string(city.size_j) + " intersections");
    }
  }
  for (const auto& [split_a, list_a] : city.regions)
    for (const auto& [split_b, list_b] : city.regions) {
      if (split_a >= split_b) continue;
      for (size_t a = 0; a < list_a.size(); ++a)
        for (size_t b = 0; b < list_b.size(); ++b)
          if (gap(list_a[a], list_b[b]) < PlanCity::kSplitGap)
            throw std::runtime_error(where + ": city regions " + split_a + "[" + std::to_string(a) + "] " +
                                     list_a[a].text() + " and " + split_b + "[" + std::to_string(b) + "] " +
                                     list_b[b].text() + " are fewer than " + std::to_string(PlanCity::kSplitGap) +
                                     " intersections apart: their roads would come within one block (72 m)");
    }
}

}  // namespace

std::string CityRegion::text() const {
  return std::to_string(i0) + "," + std::to_string(j0) + "," + std::to_string(i1) + "," + std::to_string(j1);
}

PlanCity stripCity(uint32_t seed, const std::vector<int>& widths, int rows) {
  static const char* kSplits[] = {"train", "val", "test"};
  PlanCity city;
  city.seed = seed;
  int i = 0;
  for (size_t s = 0; s < widths.size() && s < 3; ++s) {
    city.regions[kSplits[s]] = {{i, 0, i + widths[s] - 1, rows - 1}};
    i += widths[s] - 1 + PlanCity::kSplitGap;
  }
  city.size_i = i - PlanCity::kSplitGap + 1;
  city.size_j = rows;
  return city;
}

void emitCity(YAML::Emitter& out, const PlanCity& city) {
  out << YAML::Key << "city" << YAML::Value << YAML::BeginMap << YAML::Key << "seed" << YAML::Value << city.seed
      << YAML::Key << "size" << YAML::Value << YAML::Flow << YAML::BeginSeq << city.size_i << city.size_j
      << YAML::EndSeq << YAML::Key << "regions" << YAML::Value << YAML::BeginMap;
  for (const auto& [split, list] : city.regions) {
    out << YAML::Key << split << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const CityRegion& r : list) out << YAML::Flow << YAML::BeginSeq << r.i0 << r.j0 << r.i1 << r.j1 << YAML::EndSeq;
    out << YAML::EndSeq;
  }
  out << YAML::EndMap << YAML::EndMap;
}

PlanCity readCity(const YAML::Node& node, const std::string& where) {
  PlanCity city;
  try {
    city.seed = node["seed"].as<uint32_t>();
    const YAML::Node size = node["size"];
    if (!size.IsSequence() || size.size() != 2) throw std::runtime_error("size is not [I, J]");
    city.size_i = size[0].as<int>(), city.size_j = size[1].as<int>();
    if (!node["regions"].IsMap()) throw std::runtime_error("regions is not a map split -> [[I0, J0, I1, J1], ...]");
    for (const auto& entry : node["regions"]) {
      const std::string split = entry.first.as<std::string>();
      if (!entry.second.IsSequence()) throw std::runtime_error("regions of " + split + " are not a list");
      for (const YAML::Node& r : entry.second) {
        if (!r.IsSequence() || r.size() != 4) throw std::runtime_error("a region of " + split + " is not [I0, J0, I1, J1]");
        city.regions[split].push_back({r[0].as<int>(), r[1].as<int>(), r[2].as<int>(), r[3].as<int>()});
      }
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(where + ": city: " + e.what() + " (seed, size [I, J] and regions are required)");
  }
  checkCity(city, where);
  return city;
}

}  // namespace viper::dataset
