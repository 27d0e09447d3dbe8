// libFuzzer target: an arbitrary file as each image of VIPER's layout, through the package's own
// decoding paths: camera image (PNG through libpng, JPEG through OpenCV), class id PNG, instance
// PNG. Each must decode or end in std::runtime_error naming the file; a decoded image holds
// exactly width x height pixels of its channels.
// Seeds: files the package's writers make (RGB PNG and JPEG, palette and gray class PNGs,
// instance PNG).
#include "fuzz_support.h"
#include "viper/dataset/viper_images.h"

#include <stdexcept>
#include <string>

namespace {

viper::dataset::Image8 pattern(uint32_t width, uint32_t height, uint32_t channels) {
  viper::dataset::Image8 image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  for (size_t i = 0; i < image.pixels() * channels; ++i) image.data.push_back(uint8_t(i * 37 % 251));
  return image;
}

void checkDecoded(const viper::dataset::Image8& image, uint32_t channels) {
  if (image.channels != channels || image.width == 0 || image.height == 0 ||
      image.data.size() != image.pixels() * channels)
    __builtin_trap();
}

}  // namespace

void viper::fuzz::writeSeeds(const std::string& dir) {
  using namespace viper::dataset;
  writeViperColorImage(dir + "/img.png", pattern(5, 4, 3));
  writeViperColorImage(dir + "/img.jpg", pattern(16, 8, 3));
  writeViperClassImage(dir + "/cls_palette.png", pattern(5, 4, 1), ClassPalette{{{0, 0, 0}}, {{128, 64, 128}}});
  writeViperClassImage(dir + "/cls_gray.png", pattern(5, 4, 1), ClassPalette{});
  writeViperInstanceImage(dir + "/inst.png", pattern(5, 4, 3));
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace viper::dataset;
  const std::string path = viper::fuzz::scratchFile(data, size, ".png");
  try {
    checkDecoded(readViperColorImage(path), 3);
  } catch (const std::runtime_error&) {
  }
  try {
    checkDecoded(readViperClassImage(path), 1);
  } catch (const std::runtime_error&) {
  }
  try {
    const Image8 inst = readViperInstanceImage(path);
    checkDecoded(inst, 3);
    if (viperInstanceIds(inst).size() != inst.pixels()) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
