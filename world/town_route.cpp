#include "town_route.h"

#include "town_layout.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace viper {
namespace world {

std::string RouteRegion::text() const {
  return std::to_string(i0) + "," + std::to_string(j0) + "," + std::to_string(i1) + "," + std::to_string(j1);
}

int routeEdges(double route_length_m) {
  return std::max(2, int(std::ceil(route_length_m / RoadDims::kBlock)) + 1);
}

Route randomWalk(std::mt19937& rng, int edges, std::pair<int, int> start, std::pair<int, int> dir,
                 const RouteRegion* inside) {
  Route r{start};
  std::set<std::pair<int, int>> seen{start};
  int dx = dir.first, dy = dir.second;
  for (int e = 0; e < edges; ++e) {
    unsigned pick = rng() % 10;  // 6 straight, 2 left, 2 right
    int order[3] = {0, 1, 2};
    if (pick >= 6) std::swap(order[0], order[pick >= 8 ? 2 : 1]);
    bool moved = false;
    for (int k = 0; k < 3 && !moved; ++k) {
      int ndx = dx, ndy = dy;
      if (order[k] == 1) ndx = -dy, ndy = dx;   // left
      if (order[k] == 2) ndx = dy, ndy = -dx;   // right
      std::pair<int, int> next{r.back().first + ndx, r.back().second + ndy};
      if (seen.count(next)) continue;
      if (inside && !inside->contains(next.first, next.second)) continue;
      // The first and the last edges stay straight, so the route starts and ends mid-block.
      if ((e == 0 || e + 1 == edges) && order[k] != 0) continue;
      r.push_back(next);
      seen.insert(next);
      dx = ndx, dy = ndy;
      moved = true;
    }
    if (!moved) break;
  }
  return r;
}

Route routeInRegion(std::mt19937& rng, int edges, const RouteRegion& region) {
  const int w = region.i1 - region.i0 + 1, h = region.j1 - region.j0 + 1;
  static const std::pair<int, int> kHeadings[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  const int kTries = 1000;
  for (int attempt = 0; attempt < kTries; ++attempt) {
    const std::pair<int, int> start{region.i0 + int(rng() % unsigned(w)), region.j0 + int(rng() % unsigned(h))};
    const std::pair<int, int> dir = kHeadings[rng() % 4];
    Route r = randomWalk(rng, edges, start, dir, &region);
    if (int(r.size()) == edges + 1) return r;
  }
  throw std::runtime_error("--region " + region.text() + " (" + std::to_string(w) + " x " + std::to_string(h) +
                           " intersections): no route of " + std::to_string(edges) + " edges stays inside it in " +
                           std::to_string(kTries) + " tries; give a larger region or a shorter --route-length");
}

}  // namespace world
}  // namespace viper
