#include "world_run.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <sys/wait.h>

namespace viper {
namespace world_test {

int runWorld(const std::string& args, const std::string& log_path) {
  const std::string command = std::string(VIPER_WORLD_BINARY) + " " + args + " > " + log_path + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

Image readPpm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string magic;
  int maxval = 0;
  Image image;
  in >> magic >> image.width >> image.height >> maxval;
  in.get();
  if (magic != "P6" || maxval != 255 || image.width <= 0 || image.height <= 0)
    throw std::runtime_error(path + ": not a P6 PPM with maxval 255");
  image.rgb.resize(size_t(image.width) * image.height * 3);
  in.read(reinterpret_cast<char*>(image.rgb.data()), std::streamsize(image.rgb.size()));
  if (!in) throw std::runtime_error(path + ": truncated");
  return image;
}

std::string framePath(const std::string& dir, int n) {
  char name[32];
  std::snprintf(name, sizeof(name), "/frame_%06d.ppm", n);
  return dir + name;
}

uint64_t hashImage(const Image& image) {
  uint64_t h = 1469598103934665603ull;
  for (uint8_t b : image.rgb) h = (h ^ b) * 1099511628211ull;
  return h;
}

namespace {
double brightness(const Image& im, int x, int y) {
  const uint8_t* p = &im.rgb[3 * (size_t(y) * im.width + x)];
  return (p[0] + p[1] + p[2]) / 3.0;
}
}  // namespace

double meanBrightness(const Image& im) {
  double sum = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) sum += brightness(im, x, y);
  return sum / (double(im.width) * im.height);
}

double contrast(const Image& im) {
  const double mean = meanBrightness(im);
  double sum = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) sum += std::pow(brightness(im, x, y) - mean, 2);
  return std::sqrt(sum / (double(im.width) * im.height));
}

double redBlueRatio(const Image& im) {
  double r = 0, b = 0;
  for (size_t i = 0; i < im.rgb.size(); i += 3) r += im.rgb[i], b += im.rgb[i + 2];
  return r / std::max(b, 1.0);
}

int sparklePixels(const Image& im, int delta) {
  int count = 0;
  for (int y = 1; y + 1 < im.height; ++y)
    for (int x = 1; x + 1 < im.width; ++x) {
      double around = (brightness(im, x - 1, y) + brightness(im, x + 1, y) + brightness(im, x, y - 1) +
                       brightness(im, x, y + 1)) / 4.0;
      if (brightness(im, x, y) >= around + delta) ++count;
    }
  return count;
}

}  // namespace world_test
}  // namespace viper
