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
    else if (a == "--oracle") o.oracle_path = value();
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
  return o;
}

}  // namespace world
}  // namespace viper
