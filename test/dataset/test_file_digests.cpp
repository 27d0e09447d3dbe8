// The SHA-256 of files taken from their bytes as they are written (FileDigests, what generate's
// done-marker uses instead of reading the layout back): every layout writer records the checksum
// of the file it leaves on disk, as sha256OfFile (and sha256sum) compute it; a file written twice
// or changed since is not taken from the record.
#include "viper/dataset/file_digests.h"
#include "viper/dataset/sequence_marker.h"
#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_images.h"

#include "dataset_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

namespace {

using namespace viper::dataset;
using viper_dataset_test::TempDir;

Image8 noise(uint32_t w, uint32_t h, uint32_t channels, uint32_t seed) {
  std::mt19937 rng(seed);
  Image8 im;
  im.width = w, im.height = h, im.channels = channels;
  im.data.resize(im.pixels() * channels);
  for (auto& b : im.data) b = static_cast<uint8_t>(rng() % 7);  // compressible, not trivially
  return im;
}

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(sha256Hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  Sha256 pieces;  // fed in pieces, then reused
  pieces.update("a", 1);
  pieces.update("bc", 2);
  EXPECT_EQ(pieces.hex(), sha256Hex("abc", 3));
  EXPECT_EQ(pieces.hex(), sha256Hex("", 0));
}

TEST(FileDigests, EveryLayoutWriterRecordsTheChecksumOfItsFileOnDisk) {
  TempDir dir;
  FileDigests digests;
  ImageWriteOptions images;
  images.digests = &digests;
  ZipWriteOptions zip;
  zip.digests = &digests;

  const std::string img = dir / "img.png", jpg = dir / "img.jpg", cls = dir / "cls.png", inst = dir / "inst.png",
                    npz = dir / "flow.npz", bb = dir / "bb.csv";
  writeViperColorImage(img, noise(64, 48, 3, 1), images);
  writeViperColorImage(jpg, noise(64, 48, 3, 2), images);
  writeViperClassImage(cls, noise(64, 48, 1, 3), {{{128, 64, 128}}, {{244, 35, 232}}}, images);
  writeViperInstanceImage(inst, noise(64, 48, 3, 4), images);
  FlowImage flow;
  flow.width = 64, flow.height = 48;
  flow.uv.resize(2 * flow.pixels());
  for (size_t i = 0; i < flow.uv.size(); ++i) flow.uv[i] = i % 13 == 0 ? NAN : 0.25f * static_cast<float>(i % 97);
  writeViperFlow(npz, flow, zip);
  ViperBoxRow row;
  row.class_id = 24, row.instance_id = 3, row.box_2d = {{1, 2, 30, 40}};
  writeViperBoxesCsv(bb, {row, row}, &digests);

  EXPECT_EQ(digests.size(), 6u);
  for (const std::string& f : {img, jpg, cls, inst, npz, bb}) {
    const std::string recorded = digests.find(f, std::filesystem::file_size(f));
    EXPECT_EQ(recorded, sha256OfFile(f)) << f;
    EXPECT_EQ(recorded.size(), 64u) << f;
  }
  // The path as the marker names it (another spelling of the same file) finds it too.
  EXPECT_EQ(digests.find(dir.path() / "." / "bb.csv", std::filesystem::file_size(bb)), sha256OfFile(bb));
}

TEST(FileDigests, WithoutDigestsNothingIsRecorded) {
  TempDir dir;
  FileDigests digests;
  writeViperColorImage(dir / "img.png", noise(8, 8, 3, 1));
  EXPECT_EQ(digests.size(), 0u);
  EXPECT_EQ(digests.find(dir / "img.png", std::filesystem::file_size(dir / "img.png")), "");
}

TEST(FileDigests, AFileWrittenTwiceOrChangedSinceIsReadBack) {
  TempDir dir;
  FileDigests digests;
  ImageWriteOptions images;
  images.digests = &digests;
  const std::string png = dir / "inst.png";
  writeViperInstanceImage(png, noise(32, 32, 3, 1), images);
  const uint64_t size = std::filesystem::file_size(png);
  EXPECT_EQ(digests.find(png, size), sha256OfFile(png));
  EXPECT_EQ(digests.find(png, size + 1), "") << "a file of another size than written has changed";

  // Written twice (two writer threads, which of them renamed last is not known here): forgotten.
  writeViperInstanceImage(png, noise(32, 32, 3, 1), images);
  EXPECT_EQ(digests.find(png, std::filesystem::file_size(png)), "");
  EXPECT_EQ(digests.size(), 0u);
}

}  // namespace
