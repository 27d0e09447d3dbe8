// The main() that test_scene and vk_test_scene share: their command-line and exit-code contract.
#pragma once

#include "options.h"

#include <chrono>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace viper {
namespace scene {

/// Parses argv with `parse` (an OptionsError: "<name>: <message>" on stderr, exit status 2); prints
/// `usage(options)` on stdout and returns 0 if it is not empty (--help); else returns `run(options)`,
/// or 1 after "<name>: <what>" on stderr if it throws.
template <class Parse, class Usage, class Run>
int programMain(const char* name, int argc, char** argv, Parse parse, Usage usage, Run run) {
  decltype(parse(std::vector<std::string>())) options;
  try {
    options = parse(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const OptionsError& e) {
    std::cerr << name << ": " << e.what() << "\n";
    return 2;
  }
  const std::string help = usage(options);
  if (!help.empty()) {
    std::cout << help;
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << name << ": " << e.what() << "\n";
    return 1;
  }
}

/// The line --benchmark prints: "benchmark: frames=N size=WxH mean_frame_ms=M".
inline std::string benchmarkLine(const SceneOptions& o, double total_ms) {
  std::ostringstream line;
  line << "benchmark: frames=" << o.frames << " size=" << o.width << "x" << o.height
       << " mean_frame_ms=" << total_ms / o.frames << "\n";
  return line.str();
}

/// A frame's end: waits until --frame-ms after `start` when it is set, then adds the time since
/// `start` to `total_ms` (what benchmarkLine averages).
inline void endFrame(const SceneOptions& o, std::chrono::steady_clock::time_point start, double& total_ms) {
  if (o.frame_ms > 0.0) std::this_thread::sleep_until(start + std::chrono::duration<double, std::milli>(o.frame_ms));
  total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace scene
}  // namespace viper
