// Interoperability with numpy (the system's python3-numpy, which must be installed: a missing
// numpy fails these tests). numpy reads our files and finds its own float16 conversion of our
// input; we read what numpy.savez and numpy.savez_compressed write and find numpy's values. And
// PIL (python3-pil) decodes the PNGs we write (our own deflate writer) to our pixels.
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_images.h"

#include "dataset_test_util.h"
#include "flow_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <sys/wait.h>

namespace {

using namespace viper::dataset;
using viper_dataset_test::readBytes;
using viper_dataset_test::TempDir;
using viper_dataset_test::writeBytes;

// Runs `args` with the system python and the interop script; returns the exit code, output in `out`.
int runNumpy(const std::string& args, std::string& out) {
  return viper_dataset_test::runCommand(std::string(VIPER_PYTHON) + " " + VIPER_NUMPY_INTEROP_SCRIPT + " " + args, out);
}

float fromBits(uint32_t x) {
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

TEST(NumpyInterop, NumpyReadsOurFilesAsItsOwnFloat16Conversion) {
  TempDir dir;
  FlowImage flow = viper_dataset_test::zeroFlow(37, 23);
  std::mt19937 rng(5);
  std::normal_distribution<float> motion(0.0f, 30.0f);
  std::uniform_int_distribution<uint32_t> bits;
  for (size_t i = 0; i < flow.uv.size(); ++i) {
    if (i % 3 == 0) {
      uint32_t x = bits(rng);
      // Signalling NaNs are quieted by some conversions and not others: keep NaNs quiet.
      if ((x & 0x7f800000u) == 0x7f800000u && (x & 0x7fffffu) != 0) x |= 0x400000u;
      flow.uv[i] = fromBits(x);
    } else {
      flow.uv[i] = motion(rng);
    }
  }
  const float specials[] = {std::nanf(""), -std::nanf(""), std::numeric_limits<float>::infinity(), -1e30f, 65519.0f,
                            65520.0f, 0x1p-25f, 3 * 0x1p-25f, 0x1p-14f - 0x1p-25f, 1.0f + 0x1p-11f, -0.0f, 1e-40f};
  for (size_t i = 0; i < sizeof specials / sizeof specials[0]; ++i) flow.uv[7 * i + 1] = specials[i];

  std::vector<uint8_t> raw(flow.uv.size() * 4);
  std::memcpy(raw.data(), flow.uv.data(), raw.size());  // little-endian host, as the script reads '<f4'
  writeBytes(dir / "input.f32", raw);
  ZipWriteOptions stored, deflated;
  stored.deflate_level = 0;
  deflated.deflate_level = 6;
  writeViperFlow(dir / "ours_stored.npz", flow, stored);
  writeViperFlow(dir / "ours_deflated.npz", flow, deflated);
  writeViperFlow(dir / "ours_default.npz", flow);

  std::string out;
  const int rc = runNumpy("check-ours " + dir.path().string() + " 37 23 ours_stored.npz ours_deflated.npz ours_default.npz", out);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("ours_deflated.npz:v: 851 values equal"), std::string::npos) << out;
}

TEST(NumpyInterop, WeReadWhatNumpySavezWrites) {
  TempDir dir;
  std::string out;
  const int rc = runNumpy("write-numpy " + dir.path().string(), out);
  ASSERT_EQ(rc, 0) << out;
  std::ifstream manifest(dir / "manifest.txt");
  std::string name;
  uint32_t width, height;
  size_t variants = 0;
  while (manifest >> name >> width >> height) {
    ++variants;
    const FlowImage flow = readViperFlow(dir / (name + ".npz"));
    ASSERT_EQ(flow.width, width) << name;
    ASSERT_EQ(flow.height, height) << name;
    const std::vector<uint8_t> raw = readBytes(dir / (name + ".expected.f32"));
    ASSERT_EQ(raw.size(), flow.uv.size() * 4) << name;
    size_t differ = 0, nans = 0;
    for (size_t i = 0; i < flow.uv.size(); ++i) {
      float expected;
      std::memcpy(&expected, raw.data() + 4 * i, 4);
      if (std::isnan(expected)) {
        ++nans;
        differ += !std::isnan(flow.uv[i]);
      } else {
        differ += std::memcmp(&expected, &flow.uv[i], 4) != 0;
      }
    }
    EXPECT_EQ(differ, 0u) << name;
    EXPECT_EQ(nans, 2u) << name << ": the planted NaNs";
  }
  EXPECT_EQ(variants, 6u) << out;
}

TEST(NumpyInterop, PilDecodesOurPngsToOurPixels) {
  TempDir dir;
  std::mt19937 rng(11);
  // Noise rows and flat rows (the Up filter's best and worst cases), odd sizes, every level.
  auto image = [&](uint32_t w, uint32_t h, uint32_t channels) {
    Image8 im{w, h, channels, std::vector<uint8_t>(size_t(w) * h * channels)};
    for (size_t i = 0; i < im.data.size(); ++i) im.data[i] = (i / (w * channels)) % 3 == 0 ? uint8_t(rng()) : uint8_t(i / 97);
    return im;
  };
  auto save = [&](const std::string& name, const Image8& im, const char* mode) {
    writeBytes(dir / (name + ".raw"), im.data);
    writeBytes(dir / (name + ".mode"), std::vector<uint8_t>(mode, mode + std::strlen(mode)));
  };
  ClassPalette palette(40);
  for (size_t i = 0; i < palette.size(); ++i) palette[i] = {{uint8_t(i * 5), uint8_t(255 - i), uint8_t(i * 7)}};
  std::vector<uint8_t> full(768, 0);
  for (size_t i = 0; i < palette.size(); ++i) std::copy(palette[i].begin(), palette[i].end(), full.begin() + 3 * i);
  std::string names;
  for (int level : {0, 1, 6, 9}) {
    ImageWriteOptions o;
    o.png_compression_level = level;
    const std::string l = std::to_string(level);
    const Image8 rgb = image(53, 31, 3), ids = image(67, 1, 1), inst = image(1, 45, 3);
    writeViperColorImage(dir / ("img" + l + ".png"), rgb, o);
    save("img" + l, rgb, "RGB");
    writeViperClassImage(dir / ("gray" + l + ".png"), ids, {}, o);
    save("gray" + l, ids, "L");
    writeViperClassImage(dir / ("cls" + l + ".png"), ids, palette, o);
    save("cls" + l, ids, "P");
    writeBytes(dir / ("cls" + l + ".palette"), full);
    writeViperInstanceImage(dir / ("inst" + l + ".png"), inst, o);
    save("inst" + l, inst, "RGB");
    names += " img" + l + " gray" + l + " cls" + l + " inst" + l;
  }
  std::string out;
  EXPECT_EQ(runNumpy("check-png " + dir.path().string() + names, out), 0) << out;
  EXPECT_NE(out.find("cls9.png: 67x1 P equal in PIL"), std::string::npos) << out;
}

}  // namespace
