// Command line of test_scene (vk_test_scene parses the same options, less --gl-loader, plus its own).
#pragma once

#include "gl_api.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper {
namespace scene {

/// Options with their defaults.
struct SceneOptions {
  uint64_t frames = 30;
  uint32_t width = 640;
  uint32_t height = 480;
  uint64_t seed = 1;
  double fps = 15.0;  ///< simulated frame rate: frame n is rendered at time n / fps
  std::string oracle_path;  ///< empty: no oracle
  std::string dump_dir;     ///< empty: no PPM dumps
  bool benchmark = false;
  double frame_ms = 0.0;  ///< --frame-ms: each frame takes at least this long (0: as fast as it renders)
  GlLoader loader = GlLoader::kDirect;
  bool help = false;
};

/// A bad command line; the message says which option and why.
class OptionsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses argv[1..]. Accepts "--name value" and "--name=value". Throws OptionsError on unknown
/// options, missing or malformed values and values out of range.
SceneOptions parseOptions(const std::vector<std::string>& args);

/// The --help text.
std::string usage();

/// The --help lines of the options test_scene shares with vk_test_scene (frames to benchmark).
std::string sharedOptionsUsage();

}  // namespace scene
}  // namespace viper
