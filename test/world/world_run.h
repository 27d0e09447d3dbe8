// Helpers of the world tests: run the built `world` binary, read its PPM frames, image statistics.
#pragma once

#include "../common/temp_dir.h"

#include <cstdint>
#include <string>
#include <vector>

namespace viper {
namespace world_test {

/// An RGB8 image.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

/// Runs the world binary with `args` (stdout/stderr to `log_path`); returns its exit status.
int runWorld(const std::string& args, const std::string& log_path);
/// A fresh temporary directory (viper_world_test_XXXXXX), removed with its contents when the object goes.
struct TempDir : test::TempDir {
  TempDir() : test::TempDir("viper_world_test_") {}
};
/// Reads a binary PPM (P6, maxval 255); throws std::runtime_error naming the file otherwise.
Image readPpm(const std::string& path);
/// Path of frame n inside a dump directory.
std::string framePath(const std::string& dir, int n);
/// FNV-1a 64 of the pixels.
uint64_t hashImage(const Image& image);

/// Mean of (r+g+b)/3 over all pixels, 0..255.
double meanBrightness(const Image& image);
/// Standard deviation of the brightness.
double contrast(const Image& image);
/// Mean red / mean blue.
double redBlueRatio(const Image& image);
/// Pixels at least `delta` brighter than the mean of their 4 neighbours (streaks and flakes).
int sparklePixels(const Image& image, int delta);

}  // namespace world_test
}  // namespace viper
