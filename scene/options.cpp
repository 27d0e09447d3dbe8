#include "options.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace viper {
namespace scene {
namespace {

constexpr uint32_t kMaxSize = 8192;

uint64_t parseUnsigned(const std::string& option, const std::string& value, uint64_t min, uint64_t max) {
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
  if (value.empty() || value[0] == '-' || value[0] == '+' || *end != '\0' || errno == ERANGE)
    throw OptionsError(option + ": '" + value + "' is not a non-negative integer");
  if (v < min || v > max)
    throw OptionsError(option + ": " + value + " is out of range [" + std::to_string(min) + ", " +
                       std::to_string(max) + "]");
  return v;
}

double parsePositive(const std::string& option, const std::string& value) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v) || v <= 0 || v > 1e6)
    throw OptionsError(option + ": '" + value + "' is not a positive number (at most 1e6)");
  return v;
}

}  // namespace

SceneOptions parseOptions(const std::vector<std::string>& args) {
  SceneOptions o;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string name = args[i];
    std::string value;
    bool has_value = false;
    const size_t eq = name.find('=');
    if (name.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    auto take = [&]() -> std::string {
      if (has_value) return value;
      if (i + 1 >= args.size()) throw OptionsError(name + " needs a value");
      return args[++i];
    };
    if (name == "--help" || name == "-h") {
      o.help = true;
    } else if (name == "--benchmark") {
      if (has_value) throw OptionsError("--benchmark takes no value");
      o.benchmark = true;
    } else if (name == "--frames") {
      o.frames = parseUnsigned(name, take(), 1, 1000000);
    } else if (name == "--width") {
      o.width = static_cast<uint32_t>(parseUnsigned(name, take(), 1, kMaxSize));
    } else if (name == "--height") {
      o.height = static_cast<uint32_t>(parseUnsigned(name, take(), 1, kMaxSize));
    } else if (name == "--seed") {
      o.seed = parseUnsigned(name, take(), 0, UINT64_MAX);
    } else if (name == "--fps") {
      o.fps = parsePositive(name, take());
    } else if (name == "--frame-ms") {
      o.frame_ms = parsePositive(name, take());
    } else if (name == "--oracle") {
      o.oracle_path = take();
      if (o.oracle_path.empty()) throw OptionsError("--oracle needs a file name");
    } else if (name == "--dump-dir") {
      o.dump_dir = take();
      if (o.dump_dir.empty()) throw OptionsError("--dump-dir needs a directory");
    } else if (name == "--gl-loader") {
      const std::string v = take();
      if (v == "direct") o.loader = GlLoader::kDirect;
      else if (v == "egl-proc") o.loader = GlLoader::kEglProc;
      else throw OptionsError("--gl-loader: '" + v + "' is not one of direct, egl-proc");
    } else {
      throw OptionsError("unknown option '" + args[i] + "' (see --help)");
    }
  }
  return o;
}

std::string sharedOptionsUsage() {
  return "  --frames N          frames to render (default 30)\n"
         "  --width W           image width in pixels, 1..8192 (default 640)\n"
         "  --height H          image height in pixels, 1..8192 (default 480)\n"
         "  --seed S            varies building heights, car phases, rain (default 1)\n"
         "  --fps F             simulated frame rate: frame n is at time n/F seconds (default 15)\n"
         "  --oracle FILE       write the true answers per frame and draw (docs/oracle_format.md)\n"
         "  --dump-dir DIR      write each frame's color as DIR/frame_NNNNNN.ppm (read before the swap)\n"
         "  --benchmark         print the mean frame time (rendering finished: glFinish or a fence)\n"
         "  --frame-ms T        hold each frame to at least T ms, sleeping after it is finished (a program\n"
         "                      held to a frame rate: 16.667 for 60 frames/s); --benchmark then times the\n"
         "                      whole frame, the sleep included\n";
}

std::string usage() {
  return "Usage: test_scene [options]\n"
         "Renders viper's headless test scene (EGL surfaceless, OpenGL 3.3 core) into framebuffer 0,\n"
         "one eglSwapBuffers per frame. Knows nothing of capture.\n" +
         sharedOptionsUsage() +
         "  --gl-loader L       direct (libGL symbols, default) or egl-proc (eglGetProcAddress)\n"
         "  --help              this text\n"
         "Exit codes: 0 ok, 1 runtime failure (EGL/GL/file), 2 bad command line.\n";
}

}  // namespace scene
}  // namespace viper
