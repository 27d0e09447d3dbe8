// `world --print-route`: the route of a run, cheaply (no meshes drawn, no GL context), so that a
// dataset plan's routes can be checked against its regions.
#pragma once

#include "options.h"

#include <cstdio>

namespace viper {
namespace world {

/// Builds the town and the ego path of `options` and prints, one item a line:
///   route_intersections N I,J I,J ...   (global indices: a city's, or the town's own)
///   path_length_m L
///   path_points N x,y x,y ...          (every 5 m along the ego's path and its end, metres, world frame)
/// Throws what TownLayout::generate throws.
void printRoute(const Options& options, std::FILE* out);

}  // namespace world
}  // namespace viper
