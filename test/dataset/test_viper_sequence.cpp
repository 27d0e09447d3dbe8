// A whole sequence in VIPER's layout, written by the package's own writers: finding its files,
// reading every modality of a frame, and malformed sequences (missing frames, wrong sizes, bad CSV
// lines, corrupt npz and png files, stray files) where every problem names its file and the rest
// of the sequence is still read.
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"
#include "viper/dataset/viper_sequence.h"

#include "dataset_test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace {

using namespace viper::dataset;
using viper_dataset_test::readBytes;
using viper_dataset_test::TempDir;
using viper_dataset_test::writeBytes;
namespace fs = std::filesystem;

constexpr uint32_t kW = 24, kH = 16;
constexpr uint64_t kFrames = 6;

Image8 image(uint32_t w, uint32_t h, uint32_t channels, uint64_t frame) {
  Image8 im;
  im.width = w, im.height = h, im.channels = channels;
  im.data.resize(im.pixels() * channels);
  for (size_t i = 0; i < im.data.size(); ++i) im.data[i] = static_cast<uint8_t>((i * 7 + frame * 13) % 32);
  return im;
}

FlowImage flow(uint32_t w, uint32_t h, uint64_t frame) {
  FlowImage f;
  f.width = w, f.height = h;
  f.uv.resize(2 * f.pixels());
  for (size_t i = 0; i < f.uv.size(); ++i) f.uv[i] = 0.5f * static_cast<float>(i % 9) - static_cast<float>(frame);
  return f;
}

std::string path(const std::string& root, const char* modality, uint64_t frame, const char* ext) {
  return viperFramePath(root, "train", modality, "001", frame, ext);
}

// Writes a complete sequence 001 of kFrames frames, every modality.
void writeSequence(const std::string& root) {
  for (const char* m : {"img", "cls", "inst", "flow", "flowbw", "bb"})
    fs::create_directories(fs::path(root) / "train" / m / "001");
  fs::create_directories(fs::path(root) / "train" / "camera");
  std::vector<ViperCameraRow> camera;
  for (uint64_t f = 0; f < kFrames; ++f) {
    writeViperColorImage(path(root, "img", f, "png"), image(kW, kH, 3, f));
    writeViperClassImage(path(root, "cls", f, "png"), image(kW, kH, 1, f), {{{0, 0, 0}}, {{1, 2, 3}}});
    writeViperInstanceImage(path(root, "inst", f, "png"), image(kW, kH, 3, f + 1));
    if (f + 1 < kFrames) writeViperFlow(path(root, "flow", f, "npz"), flow(kW, kH, f));
    if (f > 0) writeViperFlow(path(root, "flowbw", f, "npz"), flow(kW, kH, 100 + f));
    ViperBoxRow box;
    box.class_id = 24;
    box.instance_id = static_cast<int64_t>(f + 1);
    writeViperBoxesCsv(path(root, "bb", f, "csv"), {box, box});
    ViperCameraRow row;
    row.frame = f;
    row.view[3] = static_cast<double>(f);
    camera.push_back(row);
  }
  writeViperCameraCsv(viperCameraPath(root, "train", "001"), camera);
}

std::set<ViperModality> everything() {
  return std::set<ViperModality>(allViperModalities().begin(), allViperModalities().end());
}

// The problems that mention `file` (and `what`).
size_t mentions(const std::vector<std::string>& problems, const std::string& file, const std::string& what = "") {
  size_t n = 0;
  for (const auto& p : problems)
    if (p.find(file) != std::string::npos && p.find(what) != std::string::npos) ++n;
  return n;
}

TEST(ViperSequence, ListsSplitsSequencesAndFrames) {
  TempDir dir;
  writeSequence(dir.path().string());
  fs::create_directories(dir.path() / "val" / "img" / "002");
  fs::create_directories(dir.path() / "notes");
  EXPECT_EQ(listViperSplits(dir.path().string()), (std::vector<std::string>{"train", "val"}));
  EXPECT_EQ(listViperSequences(dir.path().string(), "train"), (std::vector<std::string>{"001"}));
  EXPECT_EQ(listViperSequences(dir.path().string(), "val"), (std::vector<std::string>{"002"}));
  EXPECT_TRUE(listViperSequences(dir.path().string(), "test").empty());
  EXPECT_THROW(listViperSplits(dir / "none"), std::runtime_error);

  const ViperSequenceFiles files = scanViperSequence(dir.path().string(), "train", "001");
  EXPECT_TRUE(files.problems.empty());
  for (ViperModality m : allViperModalities()) EXPECT_TRUE(files.has(m)) << viperModalityName(m);
  EXPECT_EQ(files.files.at(ViperModality::kFlow).size(), kFrames - 1);
  EXPECT_EQ(files.camera_csv, viperCameraPath(dir.path().string(), "train", "001"));
  std::vector<std::string> problems;
  const auto camera = readViperCameraCsv(files.camera_csv, problems);
  const auto frames = viperSequenceFrames(files, camera);
  EXPECT_EQ(frames, (std::vector<uint64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(describeMissingFrames(files, camera, frames).empty()) << "no flow for the last frame, no flowbw for the first";
}

TEST(ViperSequence, ReadsEveryModalityOfAFrame) {
  TempDir dir;
  writeSequence(dir.path().string());
  const ViperSequenceFiles files = scanViperSequence(dir.path().string(), "train", "001");
  std::vector<std::string> problems;
  const auto camera = readViperCameraCsv(files.camera_csv, problems);
  const ViperFrame f = readViperFrame(files, 2, camera, everything(), problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(f.width, kW);
  EXPECT_EQ(f.height, kH);
  ASSERT_TRUE(f.img && f.cls && f.inst && f.flow && f.flowbw && f.boxes && f.camera);
  EXPECT_EQ(f.img->data, image(kW, kH, 3, 2).data);
  EXPECT_EQ(f.cls->data, image(kW, kH, 1, 2).data);
  EXPECT_EQ(f.inst->data, image(kW, kH, 3, 3).data);
  EXPECT_EQ(f.flow->uv, flow(kW, kH, 2).uv);  // halves of 0.5 steps: exact in float16
  EXPECT_EQ(f.flowbw->uv, flow(kW, kH, 102).uv);
  EXPECT_EQ(f.boxes->size(), 2u);
  EXPECT_EQ(f.camera->view[3], 2.0);
  // Only what is wanted is read.
  const ViperFrame only = readViperFrame(files, 2, camera, {ViperModality::kCls}, problems);
  EXPECT_TRUE(only.cls && !only.img && !only.flow && !only.boxes);
}

TEST(ViperSequence, MalformedFilesAreNamedAndTheRestIsRead) {
  TempDir dir;
  const std::string root = dir.path().string();
  writeSequence(root);
  // Frame 1: corrupt npz. Frame 2: no img. Frame 3: cls of the wrong size. Frame 4: truncated inst
  // png and a bad box line. Camera: a bad line for frame 5. Stray files in two folders.
  std::vector<uint8_t> npz = readBytes(path(root, "flow", 1, "npz"));
  npz[npz.size() / 3] ^= 0x55;
  writeBytes(path(root, "flow", 1, "npz"), npz);
  fs::remove(path(root, "img", 2, "png"));
  writeViperClassImage(path(root, "cls", 3, "png"), image(kW / 2, kH, 1, 3), {});
  std::vector<uint8_t> png = readBytes(path(root, "inst", 4, "png"));
  png.resize(png.size() - 40);
  writeBytes(path(root, "inst", 4, "png"), png);
  {
    std::ofstream bb(path(root, "bb", 4, "csv"), std::ios::app);
    bb << "24,9,1,2,3\n";
  }
  {
    std::ifstream in(viperCameraPath(root, "train", "001"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.rfind("\n5,") + 3, 1, "?");
    std::ofstream out(viperCameraPath(root, "train", "001"));
    out << text;
  }
  writeBytes(fs::path(path(root, "img", 0, "png")).parent_path() / "notes.txt", {'x'});
  writeBytes(path(root, "cls", 0, "png").replace(path(root, "cls", 0, "png").rfind("001_"), 3, "002"), {'x'});

  const ViperSequenceFiles files = scanViperSequence(root, "train", "001");
  EXPECT_EQ(files.problems.size(), 2u);
  EXPECT_EQ(mentions(files.problems, "notes.txt", "not <seq>_<frame>.<ext>"), 1u);
  EXPECT_EQ(mentions(files.problems, "002_00000.png", "belongs to sequence '002'"), 1u);

  std::vector<std::string> problems;
  const auto camera = readViperCameraCsv(files.camera_csv, problems);
  EXPECT_EQ(mentions(problems, files.camera_csv + ":6:", "not a number"), 1u);
  const auto frames = viperSequenceFrames(files, camera);
  EXPECT_EQ(frames.size(), kFrames) << "frame 5 still has its files";
  const auto missing = describeMissingFrames(files, camera, frames);
  EXPECT_EQ(mentions(missing, "train/img/001", "no file for frames 2"), 1u);
  EXPECT_EQ(mentions(missing, files.camera_csv, "no row for frames 5"), 1u);

  std::map<uint64_t, ViperFrame> read;
  for (uint64_t f : frames) read[f] = readViperFrame(files, f, camera, everything(), problems, kW, kH);
  EXPECT_EQ(mentions(problems, path(root, "flow", 1, "npz"), "left out"), 1u);
  EXPECT_EQ(mentions(problems, path(root, "cls", 3, "png"), "size 12x16 differs from the frame's 24x16"), 1u);
  EXPECT_EQ(mentions(problems, path(root, "inst", 4, "png"), "truncated"), 1u);
  EXPECT_EQ(mentions(problems, path(root, "bb", 4, "csv") + ":3:", "5 values, expected 28"), 1u);
  EXPECT_EQ(problems.size(), 5u) << "one per damaged file or line";

  EXPECT_TRUE(!read[1].flow && read[1].img && read[1].cls && read[1].inst && read[1].flowbw);
  EXPECT_TRUE(!read[2].img && read[2].cls && read[2].inst && read[2].flow);
  EXPECT_EQ(read[2].width, kW);
  EXPECT_TRUE(!read[3].cls && read[3].img && read[3].inst);
  EXPECT_TRUE(!read[4].inst && read[4].img && read[4].cls);
  ASSERT_TRUE(read[4].boxes);
  EXPECT_EQ(read[4].boxes->size(), 2u) << "the good lines of the box file";
  EXPECT_TRUE(!read[5].camera && read[5].img);
  for (uint64_t f : {0, 1, 2, 3, 4}) EXPECT_TRUE(read[f].camera) << f;
}

TEST(ViperSequence, SizeVoteTieGoesToTheExpectedSize) {
  TempDir dir;
  const std::string root = dir.path().string();
  fs::create_directories(fs::path(root) / "train" / "img" / "001");
  fs::create_directories(fs::path(root) / "train" / "cls" / "001");
  writeViperColorImage(path(root, "img", 0, "png"), image(8, 8, 3, 0));
  writeViperClassImage(path(root, "cls", 0, "png"), image(kW, kH, 1, 0), {});
  const ViperSequenceFiles files = scanViperSequence(root, "train", "001");
  std::vector<std::string> problems;
  const ViperFrame f = readViperFrame(files, 0, {}, everything(), problems, kW, kH);
  EXPECT_TRUE(f.cls && !f.img);
  EXPECT_EQ(mentions(problems, path(root, "img", 0, "png"), "size 8x8 differs"), 1u);
  problems.clear();
  const ViperFrame g = readViperFrame(files, 0, {}, everything(), problems);
  EXPECT_TRUE(g.img && !g.cls) << "without a hint the first modality wins";
}

TEST(ViperSequence, PrefersPngOverJpegForTheSameFrame) {
  TempDir dir;
  const std::string root = dir.path().string();
  fs::create_directories(fs::path(root) / "train" / "img" / "001");
  writeViperColorImage(path(root, "img", 0, "jpg"), image(kW, kH, 3, 0));
  writeViperColorImage(path(root, "img", 0, "png"), image(kW, kH, 3, 0));
  writeViperColorImage(path(root, "img", 1, "jpg"), image(kW, kH, 3, 1));
  const ViperSequenceFiles files = scanViperSequence(root, "train", "001");
  EXPECT_EQ(files.files.at(ViperModality::kImg).at(0), path(root, "img", 0, "png"));
  EXPECT_EQ(files.files.at(ViperModality::kImg).at(1), path(root, "img", 1, "jpg"));
  EXPECT_EQ(mentions(files.problems, path(root, "img", 0, "jpg"), "also in"), 1u);
}

}  // namespace
