#include "route_report.h"

#include "ego.h"
#include "mesh_library.h"
#include "town_layout.h"

namespace viper {
namespace world {

void printRoute(const Options& o, std::FILE* out) {
  MeshLibrary meshes;
  TownLayout town;
  town.generate(o.seed, float(o.route_length_m), meshes, o.in_city ? &o.city : nullptr);
  Ego ego;
  ego.init(town, o.ego);
  const auto [oi, oj] = town.origin();
  std::fprintf(out, "route_intersections %zu", town.route().size());
  for (const auto& [i, j] : town.route()) std::fprintf(out, " %d,%d", oi + i, oj + j);
  std::fprintf(out, "\npath_length_m %.2f\n", ego.pathLength());
  const double step_m = 5.0;
  const int n = int(ego.pathLength() / step_m) + 2;
  std::fprintf(out, "path_points %d", n);
  for (int k = 0; k < n; ++k) {
    const Vec3 p = ego.pathPoint(k + 1 < n ? k * step_m : ego.pathLength());
    std::fprintf(out, " %.2f,%.2f", p.x, p.y);
  }
  std::fprintf(out, "\n");
}

}  // namespace world
}  // namespace viper
