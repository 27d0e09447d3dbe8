#include "options.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace viper {
namespace world {

namespace {
double number(const std::string& option, const std::string& text, double lo, double hi) {
  errno = 0;
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v) || v < lo || v > hi)
    throw std::invalid_argument(option + ": '" + text + "' is not a number in [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

long integer(const std::string& option, const std::string& text, long lo, long hi) {
  errno = 0;
  char* end = nullptr;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
    throw std::invalid_argument(option + ": '" + text + "' is not an integer in [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}
// "I0,J0,I1,J1": four integers in [0, 100000], I0 <= I1 and J0 <= J1.
RouteRegion region(const std::string& text) {
  const std::string what = "--region: '" + text + "' is not I0,J0,I1,J1 (intersection indices in [0, 100000], "
                           "I0 <= I1, J0 <= J1)";
  int v[4];
  size_t from = 0;
  for (int k = 0; k < 4; ++k) {
    const size_t comma = k < 3 ? text.find(',', from) : text.size();
    if (comma == std::string::npos) throw std::invalid_argument(what);
    try {
      v[k] = int(integer("--region", text.substr(from, comma - from), 0, 100000));
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument(what);
    }
    from = comma + 1;
  }
  if (v[0] > v[2] || v[1] > v[3]) throw std::invalid_argument(what);
  return {v[0], v[1], v[2], v[3]};
}

// A city needs both options, and a region that can hold the route's intersections.
void checkCity(const Options& o, bool has_region) {
  if (has_region && !o.in_city) throw std::invalid_argument("--region needs --city-seed (the city it is a part of)");
  if (o.in_city && !has_region) throw std::invalid_argument("--city-seed needs --region (where the route may go)");
  if (!o.in_city) return;
  const int needed = routeEdges(o.route_length_m) + 1;
  if (o.city.region.intersections() < needed)
    throw std::invalid_argument("--region " + o.city.region.text() + " holds " +
                                std::to_string(o.city.region.intersections()) + " intersections; a route of " +
                                std::to_string(int(o.route_length_m)) + " m visits " + std::to_string(needed) +
                                " (give a larger region or a shorter --route-length)");
}
}  // namespace

std::string usage() {
  return "usage: world [options]\n"
         "Renders viper's procedural town (OpenGL 3.3 core, headless EGL) frame by frame.\n"
         "  --condition C     day|sunset|rain|snow|night (default day)\n"
         "  --seed N          town, traffic and people seed (default 1)\n"
         "  --frames N        frames to render (default 150)\n"
         "  --fps F           simulation steps per second (default 15)\n"
         "  --width W         frame width in pixels (default 1920)\n"
         "  --height H        frame height in pixels (default 1080)\n"
         "  --fov-deg D       vertical field of view in degrees (default 50)\n"
         "  --ego MODE        drive|ride|walk (default drive)\n"
         "  --route-length M  length of the ego route in metres (default 1000)\n"
         "  --city-seed S     a part of city S: blocks and light phases from S and the place\n"
         "  --region I0,J0,I1,J1  the city's intersections (inclusive) the route stays in\n"
         "  --print-route     print the route (global intersections, path) and exit\n"
         "  --oracle FILE     write the oracle file (true draws, objects, matrices; tests only)\n"
         "  --dump-dir DIR    write every frame as DIR/frame_NNNNNN.ppm\n"
         "  --benchmark       print the mean milliseconds per frame (rendering and swap, glFinish included)\n"
         "  --window          show the frames in an X11 window when $DISPLAY opens\n"
         "  --list-meshes     print every mesh name with its class id and exit\n"
         "  --no-effects      leave out rain streaks, snow flakes and sun glare (for tests)\n"
         "  --help            this text\n";
}

Options parseOptions(int argc, char** argv) {
  Options o;
  bool has_region = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") o.help = true;
    else if (a == "--benchmark") o.benchmark = true;
    else if (a == "--window") o.window = true;
    else if (a == "--list-meshes") o.list_meshes = true;
    else if (a == "--print-route") o.print_route = true;
    else if (a == "--no-effects") o.no_effects = true;
    else if (a == "--condition") {
      std::string v = value();
      if (!parseCondition(v, o.condition))
        throw std::invalid_argument("--condition: '" + v + "' is not one of day|sunset|rain|snow|night");
    } else if (a == "--seed") o.seed = uint32_t(integer(a, value(), 0, 4294967295L));
    else if (a == "--frames") o.frames = int(integer(a, value(), 1, 1000000));
    else if (a == "--fps") o.fps = number(a, value(), 1, 240);
    else if (a == "--width") o.width = int(integer(a, value(), 16, 8192));
    else if (a == "--height") o.height = int(integer(a, value(), 16, 8192));
    else if (a == "--fov-deg") o.fov_deg = number(a, value(), 10, 150);
    else if (a == "--route-length") o.route_length_m = number(a, value(), 100, 20000);
    else if (a == "--city-seed") {
      o.in_city = true;
      o.city.city_seed = uint32_t(integer(a, value(), 0, 4294967295L));
    } else if (a == "--region") {
      o.city.region = region(value());
      has_region = true;
    } else if (a == "--oracle") o.oracle_path = value();
    else if (a == "--dump-dir") o.dump_dir = value();
    else if (a == "--ego") {
      std::string v = value();
      if (v == "drive") o.ego = EgoMode::kDrive;
      else if (v == "ride") o.ego = EgoMode::kRide;
      else if (v == "walk") o.ego = EgoMode::kWalk;
      else throw std::invalid_argument("--ego: '" + v + "' is not one of drive|ride|walk");
    } else {
      throw std::invalid_argument("unknown option '" + a + "' (see --help)");
    }
  }
  checkCity(o, has_region);
  return o;
}

}  // namespace world
}  // namespace viper
