// Dataset plans: the presets' composition, reading a plan back and its errors, and `generate --plan`
// on the tiny preset: the whole plan in one process and the same plan in two shards (in reverse
// order, one through Slurm's array variables) give the same files, byte for byte; a second run
// skips every finished sequence.
#include "viper/dataset/dataset_plan.h"
#include "viper/dataset/viper_images.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

namespace {

namespace fs = std::filesystem;
using viper::dataset::DatasetPlan;
using viper::dataset::presetPlan;
using viper::test::readFile;
using viper::test::run;
using viper::test::tempDir;

TEST(DatasetPlan, ViperPresetHasVipersComposition) {
  const DatasetPlan plan = presetPlan("viper");
  ASSERT_EQ(plan.sequences.size(), 184u);
  std::map<std::string, size_t> per_split;
  std::map<std::string, std::map<std::string, size_t>> conditions;  // split -> condition -> sequences
  std::map<std::string, size_t> ego;
  for (const auto& s : plan.sequences) {
    ++per_split[s.split];
    ++conditions[s.split][s.condition];
    ++ego[s.ego];
    EXPECT_EQ(s.width, 1920u);
    EXPECT_EQ(s.height, 1080u);
  }
  EXPECT_EQ(per_split["train"], 77u);
  EXPECT_EQ(per_split["val"], 47u);
  EXPECT_EQ(per_split["test"], 60u);
  EXPECT_NEAR(static_cast<double>(plan.totalFrames()), 254064.0, 0.001 * 254064.0);
  for (const auto& [split, counts] : conditions) {
    ASSERT_EQ(counts.size(), 5u) << split << ": every condition";
    size_t lo = SIZE_MAX, hi = 0;
    for (const auto& [c, n] : counts) lo = std::min(lo, n), hi = std::max(hi, n);
    EXPECT_LE(hi - lo, 1u) << split << ": conditions balanced";
  }
  EXPECT_EQ(ego.size(), 3u);
  std::map<uint32_t, int> seeds;
  for (const auto& s : plan.sequences) EXPECT_EQ(++seeds[s.seed], 1) << "seed " << s.seed << " twice";
}

TEST(DatasetPlan, WrittenPlanReadsBackAndBadPlansAreNamed) {
  const std::string path = tempDir("viper_plan_") + "/small.yaml";
  const DatasetPlan small = presetPlan("small");
  viper::dataset::writePlan(path, small);
  const DatasetPlan back = viper::dataset::readPlan(path);
  ASSERT_EQ(back.sequences.size(), small.sequences.size());
  for (size_t i = 0; i < small.sequences.size(); ++i) {
    EXPECT_EQ(back.sequences[i].id, small.sequences[i].id);
    EXPECT_EQ(back.sequences[i].split, small.sequences[i].split);
    EXPECT_EQ(back.sequences[i].condition, small.sequences[i].condition);
    EXPECT_EQ(back.sequences[i].ego, small.sequences[i].ego);
    EXPECT_EQ(back.sequences[i].seed, small.sequences[i].seed);
    EXPECT_EQ(back.sequences[i].frames, small.sequences[i].frames);
  }
  EXPECT_THROW(presetPlan("huge"), std::invalid_argument);
  const std::string bad = tempDir("viper_plan_") + "/bad.yaml";
  for (const auto& [text, expected] : std::map<std::string, std::string>{
           {"sequences:\n  - {id: '001', split: holdout, frames: 3}\n", "split 'holdout'"},
           {"sequences:\n  - {id: '001', split: train, condition: fog, frames: 3}\n", "condition 'fog'"},
           {"sequences:\n  - {id: '001', split: train, frames: 0}\n", "no frames"},
           {"sequences:\n  - {id: 'a_b', split: train, frames: 3}\n", "id 'a_b'"},
           {"sequences:\n  - {id: '001', split: train, frames: 3}\n  - {id: '001', split: train, frames: 3}\n",
            "train/001 twice"},
           {"name: empty\n", "no 'sequences' list"}}) {
    std::ofstream(bad) << text;
    try {
      viper::dataset::readPlan(bad);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << "names the file: " << e.what();
    }
  }
}

std::map<std::string, std::string> files(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out[fs::relative(e.path(), root).string()] = readFile(e.path().string());
  return out;
}

// For a PNG that differs between the whole and sharded runs, whether its pixels differ too or only
// its deflate stream (once seen here and once in CI, an inst PNG with the same pixels), to tell the
// two apart when it fails.
std::string samePixels(const std::string& dir, const std::string& path) {
  if (path.size() < 4 || path.compare(path.size() - 4, 4, ".png") != 0) return "";
  try {
    const auto a = viper::dataset::readViperColorImage(dir + "/whole/" + path);
    const auto b = viper::dataset::readViperColorImage(dir + "/sharded/" + path);
    const bool same = a.width == b.width && a.height == b.height && a.data == b.data;
    return same ? " (the same pixels: only the deflate stream differs)" : " (the pixels differ)";
  } catch (const std::exception& e) {
    return std::string(" (") + e.what() + ")";
  }
}

TEST(GeneratePlan, ShardsGiveTheSameFilesAsOneProcess) {
  const std::string dir = tempDir("viper_plan_"), plan = dir + "/tiny.yaml";
  const std::string generate = VIPER_GENERATE;
  ASSERT_EQ(run(generate + " --write-plan tiny --plan " + plan + " > /dev/null"), 0);
  const std::string log = " > " + dir + "/log 2>&1";
  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + dir + "/whole" + log), 0) << readFile(dir + "/log");
  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + dir + "/sharded --task-index 1 --task-count 2" + log), 0)
      << readFile(dir + "/log");
  ASSERT_EQ(run("SLURM_ARRAY_TASK_ID=0 SLURM_ARRAY_TASK_COUNT=2 " + generate + " --plan " + plan + " --out " + dir +
                "/sharded" + log),
            0)
      << readFile(dir + "/log");
  const auto whole = files(dir + "/whole"), sharded = files(dir + "/sharded");
  ASSERT_GT(whole.size(), 3u * 10u * 6u) << "every modality of 3 sequences of 10 frames";
  EXPECT_TRUE(whole.count("val/002.done") && whole.count("test/bag/003.bag") && whole.count("train/camera/001.csv"));
  ASSERT_EQ(whole.size(), sharded.size());
  for (const auto& [path, bytes] : whole)
    EXPECT_TRUE(sharded.count(path) && sharded.at(path) == bytes) << path << samePixels(dir, path);

  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + dir + "/whole" + log), 0);
  const std::string again = readFile(dir + "/log");
  size_t finished = 0;
  for (size_t p = again.find("is finished"); p != std::string::npos; p = again.find("is finished", p + 1)) ++finished;
  EXPECT_EQ(finished, 3u) << again;
  EXPECT_NE(run(generate + " --plan " + plan + " --out " + dir + "/x --task-index 2 --task-count 2" + log), 0);
  EXPECT_NE(readFile(dir + "/log").find("task 2 of 2 does not exist"), std::string::npos);
}

TEST(GeneratePlan, MergeWritesTheManifestOnlyWhenEverySequenceIsFinished) {
  const std::string dir = tempDir("viper_plan_"), plan = dir + "/merge.yaml";
  const std::string generate = VIPER_GENERATE;
  const std::string log = " > " + dir + "/merge.log 2>&1";
  ASSERT_EQ(run(generate + " --write-plan tiny --plan " + plan + " > /dev/null"), 0);
  // Only the first of two shards: sequences 001 and 003.
  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + dir + "/m --task-index 0 --task-count 2" + log), 0);
  EXPECT_EQ(run(generate + " --merge --plan " + plan + " --out " + dir + "/m" + log), 2);
  std::string out = readFile(dir + "/merge.log");
  EXPECT_NE(out.find("missing val/002: not generated"), std::string::npos) << out;
  EXPECT_NE(out.find("1 of 3 planned sequences are not finished"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir + "/m/MANIFEST.sha256"));

  ASSERT_EQ(run(generate + " --plan " + plan + " --out " + dir + "/m --task-index 1 --task-count 2" + log), 0);
  ASSERT_EQ(run(generate + " --merge --plan " + plan + " --out " + dir + "/m" + log), 0) << readFile(dir + "/merge.log");
  EXPECT_EQ(run("cd " + dir + "/m && sha256sum --quiet -c MANIFEST.sha256"), 0) << "sha256sum checks the manifest";
  const std::string md = readFile(dir + "/m/manifest.md");
  EXPECT_NE(md.find("3 sequences, 30 frames"), std::string::npos) << md;
  EXPECT_NE(md.find("| val | sunset | 1 | 10 |"), std::string::npos) << md;

  fs::remove(dir + "/m/test/flow/003/003_00004.npz");
  EXPECT_EQ(run(generate + " --merge --plan " + plan + " --out " + dir + "/m" + log), 2);
  out = readFile(dir + "/merge.log");
  EXPECT_NE(out.find("missing test/003: "), std::string::npos) << out;
  EXPECT_NE(out.find("003_00004.npz is missing"), std::string::npos) << out;
}

}  // namespace
