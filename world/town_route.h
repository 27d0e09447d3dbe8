// The ego route: a self-avoiding random walk over the grid of intersections. A town of its own
// walks from (0, 0) without bounds; a sequence of a city walks inside a rectangle of the city's
// global intersection indices (its split's region).
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace viper {
namespace world {

/// Intersections (i, j) in visiting order.
using Route = std::vector<std::pair<int, int>>;

/// A rectangle of intersections, bounds inclusive.
struct RouteRegion {
  int i0 = 0, j0 = 0, i1 = 0, j1 = 0;

  bool contains(int i, int j) const { return i >= i0 && i <= i1 && j >= j0 && j <= j1; }
  int intersections() const { return (i1 - i0 + 1) * (j1 - j0 + 1); }
  /// "I0,J0,I1,J1", as --region takes it.
  std::string text() const;
};

/// The place of a sequence in a city: the city's seed (static scenery and light phases) and the
/// region its route stays in.
struct CityPlace {
  uint32_t city_seed = 0;
  RouteRegion region;
};

/// Edges of a route of about `route_length_m` (the first and the last are straight half blocks).
int routeEdges(double route_length_m);

/// Walks `edges` edges from `start` heading `dir` (a unit step): 6 in 10 straight on, else left or
/// right, never onto an intersection already visited nor, when `inside` is given, out of it; the
/// first and the last edges go straight. Stops early when every way is blocked.
Route randomWalk(std::mt19937& rng, int edges, std::pair<int, int> start, std::pair<int, int> dir,
                 const RouteRegion* inside);

/// A route of exactly `edges` edges inside `region`: start and heading drawn from `rng`, a blocked
/// walk drawn again (up to 1000 times). Throws std::runtime_error naming the region and the
/// length when none fits.
Route routeInRegion(std::mt19937& rng, int edges, const RouteRegion& region);

}  // namespace world
}  // namespace viper
