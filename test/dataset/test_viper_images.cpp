// VIPER's image files: camera images (PNG/JPEG), class id images (palette or gray PNG) and instance
// images (RGB PNG); exact round trips, what other readers (OpenCV) see in our files, every PNG
// color type we accept or refuse, and damaged files.
#include "viper/dataset/viper_images.h"

#include "../common/rgb_image.h"
#include "dataset_test_util.h"

#include <boost/crc.hpp>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <random>

namespace {

using namespace viper::dataset;
using namespace viper_dataset_test;

Image8 makeImage(uint32_t w, uint32_t h, uint32_t channels, uint32_t seed) {
  Image8 im;
  im.width = w, im.height = h, im.channels = channels;
  im.data.resize(im.pixels() * channels);
  std::mt19937 rng(seed);
  for (auto& b : im.data) b = static_cast<uint8_t>(rng());
  return im;
}

// A smooth picture (JPEG's kind of input): gradients plus a square.
Image8 smoothImage(uint32_t w, uint32_t h) {
  return viper::test::rgbImage(w, h, [&](uint32_t x, uint32_t y) {
    const bool square = x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2;
    return std::array<uint8_t, 3>{static_cast<uint8_t>(255 * x / w), static_cast<uint8_t>(255 * y / h),
                                  static_cast<uint8_t>(square ? 200 : 40)};
  });
}

ClassPalette viperPalette() {
  // The first classes of VIPER's classes.csv (unlabeled, ambiguous, sky, road, sidewalk).
  return {{{0, 0, 0}}, {{111, 74, 0}}, {{70, 130, 180}}, {{128, 64, 128}}, {{244, 35, 232}}};
}

TEST(ViperImages, ColorPngRoundTripsExactly) {
  TempDir dir;
  for (int level : {0, 1, 9}) {
    const Image8 im = makeImage(33, 17, 3, 1 + level);
    ImageWriteOptions o;
    o.png_compression_level = level;
    writeViperColorImage(dir / "a.png", im, o);
    const Image8 back = readViperColorImage(dir / "a.png");
    EXPECT_EQ(back.width, 33u);
    EXPECT_EQ(back.height, 17u);
    EXPECT_EQ(back.channels, 3u);
    EXPECT_EQ(back.data, im.data) << "level " << level;
    // OpenCV (BGR) sees the same pixels.
    const cv::Mat cvim = cv::imread(dir / "a.png", cv::IMREAD_UNCHANGED);
    ASSERT_EQ(cvim.type(), CV_8UC3);
    EXPECT_EQ(cvim.at<cv::Vec3b>(5, 7)[2], im.data[3 * (5 * 33 + 7)]);
  }
}

// Level 1 is ISA-L's deflate, the others libdeflate's: at 1080p, a camera-like image and noise
// (which no deflate shrinks: stored blocks) read back exactly through libpng and OpenCV's decoder,
// and a smooth image is smaller than stored at every level.
TEST(ViperImages, EveryDeflateLevelRoundTripsFullHdImagesAndNoise) {
  TempDir dir;
  const Image8 noise = makeImage(1920, 1080, 3, 5), smooth = smoothImage(1920, 1080);
  for (int level : {0, 1, 2, 9}) {
    for (const Image8* im : {static_cast<const Image8*>(&noise), static_cast<const Image8*>(nullptr)}) {
      const Image8& image = im ? *im : smooth;
      ImageWriteOptions o;
      o.png_compression_level = level;
      const std::string path = dir / "big.png";
      writeViperColorImage(path, image, o);
      const std::string what = std::string(im ? "noise" : "smooth") + " at level " + std::to_string(level);
      EXPECT_TRUE(readViperColorImage(path).data == image.data) << what;
      const cv::Mat cvim = cv::imread(path, cv::IMREAD_UNCHANGED);
      ASSERT_EQ(cvim.type(), CV_8UC3) << what;
      EXPECT_EQ(cvim.at<cv::Vec3b>(1079, 1919)[0], image.data[3 * (1079 * 1920 + 1919) + 2]) << what;
      const auto size = std::filesystem::file_size(path);
      if (!im && level > 0) EXPECT_LT(size, image.data.size() / 4) << what;
      if (im) EXPECT_LT(size, image.data.size() + image.data.size() / 100) << what << ": stored blocks";
    }
  }
}

// Fills this thread's stack below the caller with `value`: what a writer finds there (in variables
// a library leaves uninitialised) must not change its bytes.
__attribute__((noinline)) void dirtyStack(uint32_t value) {
  volatile uint32_t junk[64 * 1024];
  for (size_t i = 0; i < sizeof junk / sizeof junk[0]; ++i) junk[i] = value;
}

// The same image gives the same file whatever ran before on the thread (ISA-L's stream state was
// once left partly uninitialised, and 6 of 120 files of a generate run then differed between runs).
TEST(ViperImages, SameBytesWhateverRanBefore) {
  TempDir dir;
  const Image8 image = smoothImage(640, 480);
  ImageWriteOptions o;  // level 1
  std::vector<std::vector<uint8_t>> files;
  for (uint32_t value : {0u, 9u, 12u, 0x000a000au, 0xffffffffu}) {  // small numbers: what a field of sizes would hold
    dirtyStack(value);
    const std::string path = dir / ("same_" + std::to_string(value) + ".png");
    writeViperColorImage(path, image, o);
    files.push_back(readBytes(path));
  }
  for (size_t i = 1; i < files.size(); ++i) EXPECT_TRUE(files[i] == files[0]) << "file " << i << " differs from file 0";
}

TEST(ViperImages, JpegRoundTripIsCloseAndReadsAsRgb) {
  TempDir dir;
  const Image8 im = smoothImage(64, 48);
  writeViperColorImage(dir / "a.jpg", im);
  const Image8 back = readViperColorImage(dir / "a.jpg");
  ASSERT_EQ(back.data.size(), im.data.size());
  double error = 0;
  for (size_t i = 0; i < im.data.size(); ++i) error += std::abs(int(back.data[i]) - int(im.data[i]));
  EXPECT_LT(error / im.data.size(), 3.0) << "mean absolute error at quality 95";
  EXPECT_GT(back.data[3 * (20 * 64 + 20) + 2], 150) << "blue channel of the square: RGB order kept";
  // A JPEG under a .png name is still recognised by its bytes.
  writeBytes(dir / "b.png", readBytes(dir / "a.jpg"));
  EXPECT_EQ(readViperColorImage(dir / "b.png").data, back.data);
}

TEST(ViperImages, ColorReaderExpandsGrayAlphaAnd16Bit) {
  TempDir dir;
  cv::Mat gray(4, 5, CV_8UC1);
  for (int i = 0; i < 20; ++i) gray.data[i] = static_cast<uint8_t>(i * 12);
  ASSERT_TRUE(cv::imwrite(dir / "g.png", gray));
  Image8 g = readViperColorImage(dir / "g.png");
  ASSERT_EQ(g.channels, 3u);
  EXPECT_EQ(g.data[3 * 7], 84);
  EXPECT_EQ(g.data[3 * 7 + 2], 84);

  cv::Mat bgra(2, 3, CV_8UC4, cv::Scalar(10, 20, 30, 128));
  ASSERT_TRUE(cv::imwrite(dir / "a.png", bgra));
  Image8 a = readViperColorImage(dir / "a.png");
  EXPECT_EQ(a.channels, 3u);
  EXPECT_EQ(a.data[0], 30);  // R
  EXPECT_EQ(a.data[2], 10);  // B

  cv::Mat deep(2, 2, CV_16UC3, cv::Scalar(0, 256 * 100, 65535));
  ASSERT_TRUE(cv::imwrite(dir / "d.png", deep));
  Image8 d = readViperColorImage(dir / "d.png");
  EXPECT_EQ(d.data[0], 255);
  EXPECT_EQ(d.data[1], 100);
  EXPECT_EQ(d.data[2], 0);
}

TEST(ViperImages, ClassIdsRoundTripAsPaletteAndAsGray) {
  TempDir dir;
  Image8 ids = makeImage(40, 30, 1, 7);
  for (auto& b : ids.data) b %= 32;
  writeViperClassImage(dir / "p.png", ids, viperPalette());
  EXPECT_EQ(readViperClassImage(dir / "p.png").data, ids.data);
  // Viewers that expand the palette see the class colors (OpenCV expands palettes to BGR).
  const cv::Mat shown = cv::imread(dir / "p.png", cv::IMREAD_COLOR);
  ASSERT_EQ(shown.type(), CV_8UC3);
  for (int i = 0; i < 40 * 30; ++i) {
    const uint8_t id = ids.data[i];
    const cv::Vec3b bgr = shown.at<cv::Vec3b>(i / 40, i % 40);
    const auto expected = id < 5 ? viperPalette()[id] : std::array<uint8_t, 3>{{0, 0, 0}};
    ASSERT_EQ(bgr[2], expected[0]) << "pixel " << i << " id " << int(id);
    ASSERT_EQ(bgr[0], expected[2]);
  }
  writeViperClassImage(dir / "g.png", ids, {});
  EXPECT_EQ(readViperClassImage(dir / "g.png").data, ids.data);
  const cv::Mat gray = cv::imread(dir / "g.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(gray.type(), CV_8UC1);
  EXPECT_EQ(gray.data[17], ids.data[17]);
}

TEST(ViperImages, InstanceImagesRoundTripAndSplit) {
  TempDir dir;
  Image8 inst;
  inst.width = 3, inst.height = 1, inst.channels = 3;
  inst.data = {24, 0, 5, 20, 1, 2, 3, 0, 0};  // car 5, person 258, road without instance
  writeViperInstanceImage(dir / "i.png", inst);
  const Image8 back = readViperInstanceImage(dir / "i.png");
  EXPECT_EQ(back.data, inst.data);
  EXPECT_EQ(viperInstanceIds(back), (std::vector<int32_t>{5, 258, 0}));
  EXPECT_EQ(viperInstanceClasses(back), (std::vector<uint8_t>{24, 20, 3}));
}

TEST(ViperImages, RefusesImagesThatCannotHoldTheirLabels) {
  TempDir dir;
  writeViperColorImage(dir / "rgb.png", makeImage(4, 4, 3, 1));
  expectErrorNaming([&] { readViperClassImage(dir / "rgb.png"); }, {dir / "rgb.png", "RGB", "class ids"}, "rgb as cls");
  Image8 ids = makeImage(4, 4, 1, 2);
  writeViperClassImage(dir / "ids.png", ids, {});
  expectErrorNaming([&] { readViperInstanceImage(dir / "ids.png"); }, {dir / "ids.png", "gray", "instance"}, "gray as inst");
  cv::Mat deep(2, 2, CV_16UC1, cv::Scalar(300));
  ASSERT_TRUE(cv::imwrite(dir / "deep.png", deep));
  expectErrorNaming([&] { readViperClassImage(dir / "deep.png"); }, {dir / "deep.png", "16-bit"}, "16-bit cls");
  writeViperColorImage(dir / "c.jpg", smoothImage(8, 8));
  expectErrorNaming([&] { readViperClassImage(dir / "c.jpg"); }, {dir / "c.jpg", "JPEG"}, "jpeg cls");
  expectErrorNaming([&] { readViperInstanceImage(dir / "c.jpg"); }, {dir / "c.jpg", "JPEG"}, "jpeg inst");
}

TEST(ViperImages, DamagedFilesThrowNamingTheFile) {
  TempDir dir;
  expectErrorNaming([&] { readViperColorImage(dir / "none.png"); }, {dir / "none.png", "cannot open"}, "missing");
  writeBytes(dir / "text.png", std::vector<uint8_t>{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'});
  expectErrorNaming([&] { readViperColorImage(dir / "text.png"); }, {dir / "text.png", "not a PNG"}, "not png");

  const Image8 im = makeImage(64, 64, 3, 3);
  writeViperColorImage(dir / "good.png", im);
  std::vector<uint8_t> bytes = readBytes(dir / "good.png");
  writeBytes(dir / "cut.png", std::vector<uint8_t>(bytes.begin(), bytes.begin() + bytes.size() / 2));
  expectErrorNaming([&] { readViperColorImage(dir / "cut.png"); }, {dir / "cut.png", "truncated"}, "truncated");
  std::vector<uint8_t> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x40;  // inside the image data: a CRC error
  writeBytes(dir / "flip.png", flipped);
  expectErrorNaming([&] { readViperColorImage(dir / "flip.png"); }, {dir / "flip.png", "corrupt PNG"}, "flipped");

  writeViperColorImage(dir / "good.jpg", smoothImage(32, 32));
  bytes = readBytes(dir / "good.jpg");
  writeBytes(dir / "cut.jpg", std::vector<uint8_t>(bytes.begin(), bytes.begin() + bytes.size() / 2));
  expectErrorNaming([&] { readViperColorImage(dir / "cut.jpg"); }, {dir / "cut.jpg", "truncated JPEG"}, "jpeg cut");
}

// Found while fuzzing readViperColorImage (the viper_images target): a 791-byte JPEG, the
// package's own with its frame header saying 30000 x 30000, made OpenCV allocate 2.7 GB and
// decode gray; a PNG header can say the same (with its CRC right). Both are refused from the header.
TEST(ViperImages, RegressionFuzzHugeDeclaredSizeIsRefusedBeforeDecoding) {
  TempDir dir;
  const std::string jpeg = "test/fuzz/regressions/viper_images/jpeg_declares_30000x30000.jpg";
  ASSERT_LT(readBytes(jpeg).size(), 1000u);
  expectErrorNaming([&] { readViperColorImage(jpeg); }, {jpeg, "JPEG declares 30000x30000 pixels"}, "jpeg");

  writeViperColorImage(dir / "small.png", makeImage(4, 4, 3, 5));
  std::vector<uint8_t> png = readBytes(dir / "small.png");
  // IHDR is the first chunk: length (4), "IHDR" (4), width and height (4 each) at byte 16, CRC at 29.
  for (int k = 0; k < 4; ++k) png[16 + k] = png[20 + k] = static_cast<uint8_t>(20000u >> (24 - 8 * k));
  boost::crc_32_type crc;
  crc.process_bytes(png.data() + 12, 17);
  for (int k = 0; k < 4; ++k) png[29 + k] = static_cast<uint8_t>(crc.checksum() >> (24 - 8 * k));
  writeBytes(dir / "huge.png", png);
  for (auto* read : {&readViperColorImage, &readViperClassImage, &readViperInstanceImage})
    expectErrorNaming([&] { read(dir / "huge.png"); }, {dir / "huge.png", "PNG declares 20000x20000 pixels"}, "png");

  // The limit refuses nothing VIPER writes: 1920 x 1080 still reads.
  writeViperColorImage(dir / "hd.jpg", smoothImage(1920, 1080));
  EXPECT_EQ(readViperColorImage(dir / "hd.jpg").pixels(), 1920u * 1080u);
}

TEST(ViperImages, RandomDamageEitherThrowsOrGivesTheRightSize) {
  TempDir dir;
  const Image8 im = makeImage(48, 20, 3, 4);
  writeViperInstanceImage(dir / "good.png", im);
  const std::vector<uint8_t> bytes = readBytes(dir / "good.png");
  std::mt19937 rng(11);
  int threw = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<uint8_t> damaged = bytes;
    if (trial % 3 == 0) damaged.resize(rng() % bytes.size());
    else
      for (int k = 0; k < 1 + trial % 4; ++k) damaged[rng() % damaged.size()] ^= static_cast<uint8_t>(1 + rng() % 255);
    writeBytes(dir / "d.png", damaged);
    try {
      const Image8 back = readViperInstanceImage(dir / "d.png");
      EXPECT_EQ(back.data.size(), back.pixels() * 3);
    } catch (const std::runtime_error& e) {
      ++threw;
      EXPECT_EQ(std::string(e.what()).rfind(dir / "d.png", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(threw, 200);
}

TEST(ViperImages, WritersCheckTheirInput) {
  TempDir dir;
  Image8 bad = makeImage(4, 4, 3, 1);
  bad.data.pop_back();
  EXPECT_THROW(writeViperColorImage(dir / "a.png", bad), std::invalid_argument);
  EXPECT_THROW(writeViperClassImage(dir / "a.png", makeImage(4, 4, 3, 1), {}), std::invalid_argument);
  EXPECT_THROW(writeViperInstanceImage(dir / "a.png", makeImage(0, 4, 3, 1)), std::invalid_argument);
  expectErrorNaming([&] { writeViperColorImage(dir / "no/such/a.png", makeImage(4, 4, 3, 1)); },
                    {dir / "no/such/a.png", "cannot write"}, "missing folder");
  EXPECT_FALSE(std::filesystem::exists(dir / "a.png")) << "nothing written for bad input";
}

}  // namespace
