// The city of a dataset plan: the presets' partition into strips, its YAML and its checks.
#pragma once

#include "viper/dataset/dataset_plan.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace viper::dataset {

/// A city of `rows` intersections along y cut into strips along x, one per split (train, val,
/// test) of `widths[s]` intersections, PlanCity::kSplitGap apart.
PlanCity stripCity(uint32_t seed, const std::vector<int>& widths, int rows);

/// Emits the `city` map: {seed, size: [I, J], regions: {split: [[I0, J0, I1, J1], ...]}}.
void emitCity(YAML::Emitter& out, const PlanCity& city);

/// Reads the `city` map; throws std::runtime_error starting with `where` when a field is missing or
/// malformed, a region lies outside the city or has its corners out of order, or two splits'
/// regions are closer than kSplitGap.
PlanCity readCity(const YAML::Node& node, const std::string& where);

}  // namespace viper::dataset
