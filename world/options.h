// Command line of the `world` program.
#pragma once

#include "conditions.h"
#include "ego.h"
#include "town_route.h"

#include <cstdint>
#include <string>

namespace viper {
namespace world {

/// Settings of one run (defaults as documented in docs/world.md).
struct Options {
  Condition condition = Condition::kDay;
  uint32_t seed = 1;
  int frames = 150;
  double fps = 15.0;
  int width = 1920;
  int height = 1080;
  double fov_deg = 50.0;  ///< vertical field of view
  EgoMode ego = EgoMode::kDrive;
  double route_length_m = 1000.0;
  bool in_city = false;  ///< --city-seed given: `city` holds the seed and the region
  CityPlace city;
  std::string oracle_path;
  std::string dump_dir;
  bool benchmark = false;
  bool window = false;
  bool list_meshes = false;
  bool print_route = false;
  bool no_effects = false;  ///< tests only: leave out rain, snow and glare
  bool help = false;
};

/// Parses argv. Throws std::invalid_argument with a message naming the option and the accepted
/// values on an unknown option, a missing or malformed value, or a value out of range; also for a
/// --region without --city-seed (or the reverse), a region whose corners are out of order or out of
/// [0, 100000], or one with fewer intersections than the route visits.
Options parseOptions(int argc, char** argv);

/// The --help text.
std::string usage();

}  // namespace world
}  // namespace viper
