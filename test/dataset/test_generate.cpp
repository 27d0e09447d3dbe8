// The generate command (no roscore) on the world's capture made at build time and on its raw bag
// (capture_to_bag): the same sequence from either (with writer threads or without) and on every
// vector path of the kernels, a finished sequence skipped and a changed one
// redone, the marker's checksums taken as the files were written equal to those of the files on disk, two generators of one sequence taking turns, a damaged capture's intact frames kept, an output that cannot be written an error with no
// marker. That its ground truth equals the nodes' is viper_layout_roundtrip.test.
#include "viper/dataset/sequence_lock.h"
#include "viper/dataset/sequence_marker.h"

#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <thread>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using viper::test::readFile;
using viper::test::run;
using viper::test::tempDir;

struct Result {
  int rc = 0;
  std::string output;
};

Result runGenerate(const std::string& input, const std::string& root, const std::string& extra = "") {
  const std::string log = tempDir("viper_generate_") + "/last.log";
  Result r;
  r.rc = run(std::string(VIPER_GENERATE) + " --input " + input + " --labels " + VIPER_WORLD_LABELS + " --out " + root +
             " " + extra + " > " + log + " 2>&1");
  r.output = readFile(log);
  return r;
}

// Every regular file under `root`, by relative path, with its bytes.
std::map<std::string, std::string> files(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out[fs::relative(e.path(), root).string()] = readFile(e.path().string());
  return out;
}

// The files of `after` whose bytes differ from `before`'s (or are missing in either), in one line
// with sizes and the first differing byte: generate writes the same bytes every time, and when it
// does not, this says where (a CI log keeps a few lines of a failure, not two PNGs' bytes).
std::string differingFiles(const std::map<std::string, std::string>& before,
                           const std::map<std::string, std::string>& after) {
  std::string out;
  size_t n = 0;
  auto note = [&](const std::string& text) {
    if (++n <= 6) out += (out.empty() ? "" : "; ") + text;
  };
  for (const auto& [path, bytes] : before) {
    const auto other = after.find(path);
    if (other == after.end()) {
      note(path + " missing");
      continue;
    }
    if (other->second == bytes) continue;
    size_t i = 0;
    while (i < bytes.size() && i < other->second.size() && bytes[i] == other->second[i]) ++i;
    note(path + " (" + std::to_string(bytes.size()) + " -> " + std::to_string(other->second.size()) +
         " bytes, first difference at byte " + std::to_string(i) + ")");
  }
  for (const auto& [path, bytes] : after)
    if (!before.count(path)) note(path + " new");
  if (n > 6) out += "; and " + std::to_string(n - 6) + " more";
  return out;
}

const std::string kCapture = VIPER_TEST_DATA "/world_roundtrip.vcap";
const std::string kRawBag = VIPER_TEST_DATA "/world_raw.bag";

// Also: writer threads (the capture's run has two, the bag's none) change no byte.
TEST(Generate, CaptureAndItsRawBagGiveTheSameSequence) {
  const std::string a = tempDir("viper_generate_") + "/from_capture", b = tempDir("viper_generate_") + "/from_bag";
  const Result ra = runGenerate(kCapture, a, "--writer-threads 2"), rb = runGenerate(kRawBag, b, "--writer-threads 0");
  ASSERT_EQ(ra.rc, 0) << ra.output;
  ASSERT_EQ(rb.rc, 0) << rb.output;
  EXPECT_NE(ra.output.find("train/001: 20 frames (0 dropped"), std::string::npos) << ra.output;
  EXPECT_NE(ra.output.find("layout writers"), std::string::npos) << "the stage table names the writer threads: " << ra.output;
  EXPECT_EQ(rb.output.find("layout writers"), std::string::npos) << rb.output;
  // The progress: a bag knows its frames; a capture is read to its end, so its total is unknown
  // (not a full bar of "1/0 frames"): lines at 1-9, 10 and 20 frames.
  EXPECT_NE(rb.output.find("20/20 frames"), std::string::npos) << rb.output;
  EXPECT_EQ(ra.output.find("/0 frames"), std::string::npos) << ra.output;
  for (const char* line : {"generate train/001 1 frames (total unknown)", "generate train/001 9 frames (total unknown)",
                           "generate train/001 20 frames (total unknown)"})
    EXPECT_NE(ra.output.find(line), std::string::npos) << line << " in: " << ra.output;
  EXPECT_EQ(ra.output.find("11 frames (total unknown)"), std::string::npos) << ra.output;
  const auto fa = files(a), fb = files(b);
  for (const char* f : {"train/img/001/001_00000.png", "train/cls/001/001_00019.png", "train/inst/001/001_00007.png",
                        "train/flow/001/001_00000.npz", "train/flowbw/001/001_00019.npz", "train/bb/001/001_00003.csv",
                        "train/camera/001.csv", "train/bag/001.bag", "train/001.done"})
    EXPECT_TRUE(fa.count(f)) << f << " not written";
  ASSERT_EQ(fa.size(), fb.size());
  for (const auto& [path, bytes] : fa) {
    const auto other = fb.find(path);
    ASSERT_NE(other, fb.end()) << path;
    EXPECT_TRUE(bytes == other->second) << path << " differs";
  }
  // The marker lists every file with its checksum.
  const viper::dataset::SequenceMarker m = viper::dataset::readSequenceMarker(a + "/train/001.done");
  EXPECT_EQ(m.frames, 20u);
  EXPECT_EQ(m.files.size(), fa.size() - 1);
  EXPECT_EQ(viper::dataset::verifySequence(a, m), "");
}

// The training formats generate writes beside the layout and the bag are, byte for byte, what
// export_training writes from that bag (whose files test_training_formats checks against the formats'
// reference code), and COCO's amodal file besides, with an annotation for every visible one; they
// are the sequence's, listed in its marker; a sequence name the formats cannot number is an error.
TEST(Generate, TrainingFormatsAreExportTrainingsOfItsBag) {
  const std::string root = tempDir("viper_generate_") + "/gen", again = tempDir("viper_generate_") + "/export";
  const Result r = runGenerate(kRawBag, root, "--frames 8 --outputs bag,cityscapes,coco,kitti --seq 007");
  ASSERT_EQ(r.rc, 0) << r.output;
  const std::string training = root + "/train/training/007";
  ASSERT_EQ(run(std::string(VIPER_EXPORT_TRAINING) + " --bag " + root + "/train/bag/007.bag --seq 7 --out " + again +
                " > " + again + ".log 2>&1"),
            0)
      << readFile(again + ".log");
  auto generated = files(training);
  const std::string amodal = "coco/annotations/instances_amodal_train_000007.json";
  ASSERT_TRUE(generated.count(amodal)) << "no amodal file";
  const std::string amodal_json = generated[amodal];
  generated.erase(amodal);
  const auto exported = files(again);
  EXPECT_EQ(differingFiles(exported, generated), "");
  for (const char* f : {"cityscapes/gtFine/train/viper/viper_000007_000003_gtFine_instanceIds.png",
                        "cityscapes/leftImg8bit/train/viper/viper_000007_000007_leftImg8bit.png",
                        "coco/annotations/instances_train_000007.json", "kitti/train/000007/flow_occ/000006_10.png",
                        "kitti/train/000007/proj_depth/groundtruth/image_02/0000000007.png"})
    EXPECT_TRUE(generated.count(f)) << f << " not written";
  auto count = [](const std::string& json, const std::string& key) {
    size_t n = 0;
    for (size_t at = json.find(key); at != std::string::npos; at = json.find(key, at + 1)) ++n;
    return n;
  };
  const size_t visible = count(generated["coco/annotations/instances_train_000007.json"], "\"segmentation\"");
  EXPECT_GT(visible, 0u);
  EXPECT_GE(count(amodal_json, "\"segmentation\""), visible);
  const viper::dataset::SequenceMarker m = viper::dataset::readSequenceMarker(root + "/train/007.done");
  size_t listed = 0;
  for (const auto& f : m.files) listed += f.relative_path.rfind("train/training/007/", 0) == 0;
  EXPECT_EQ(listed, generated.size() + 1);
  EXPECT_EQ(viper::dataset::verifySequence(root, m), "");

  const Result bad = runGenerate(kRawBag, tempDir("viper_generate_") + "/bad", "--frames 2 --outputs coco --seq a7");
  EXPECT_NE(bad.rc, 0);
  EXPECT_NE(bad.output.find("must be 1 to 6 digits, got 'a7'"), std::string::npos) << bad.output;
}

// The per-pixel kernels' paths (VIPER_INSTRUCTIONS caps them: instructions.h) write the same files:
// a dataset generated on nodes with other CPUs is the same dataset. A CPU without a path runs the
// widest it has below it (that run then repeats another).
TEST(Generate, EveryVectorPathWritesTheSameFiles) {
  const std::string dir = tempDir("viper_generate_") + "/paths";
  ASSERT_EQ(runGenerate(kRawBag, dir + "/widest", "--outputs layout").rc, 0);
  const auto widest = files(dir + "/widest");
  for (const char* path : {"avx512", "avx2", "scalar"}) {
    SCOPED_TRACE(path);
    ::setenv("VIPER_INSTRUCTIONS", path, 1);
    const Result r = runGenerate(kRawBag, dir + "/" + path, "--outputs layout");
    ::unsetenv("VIPER_INSTRUCTIONS");
    ASSERT_EQ(r.rc, 0) << r.output;
    EXPECT_EQ(differingFiles(widest, files(dir + "/" + path)), "");
  }
  ::setenv("VIPER_INSTRUCTIONS", "sse9", 1);
  const Result bad = runGenerate(kRawBag, dir + "/bad", "--outputs layout");
  ::unsetenv("VIPER_INSTRUCTIONS");
  EXPECT_EQ(bad.rc, 0);
  EXPECT_NE(bad.output.find("VIPER_INSTRUCTIONS=sse9 is not one of"), std::string::npos) << bad.output;
}

TEST(Generate, FinishedIsSkippedChangedIsRedone) {
  const std::string root = tempDir("viper_generate_") + "/resume";
  ASSERT_EQ(runGenerate(kRawBag, root).rc, 0);
  const fs::path png = fs::path(root) / "train/cls/001/001_00004.png";
  const auto written = fs::last_write_time(png);
  const auto first = files(root);

  Result again = runGenerate(kRawBag, root);
  EXPECT_EQ(again.rc, 0);
  EXPECT_NE(again.output.find("is finished"), std::string::npos) << again.output;
  EXPECT_EQ(fs::last_write_time(png), written) << "a finished sequence was written again";

  std::ofstream(png, std::ios::app) << "x";  // damaged after the run
  ASSERT_TRUE(readFile(png.string()) == first.at(fs::relative(png, root).string()) + "x") << "could not damage " << png;
  again = runGenerate(kRawBag, root);
  EXPECT_EQ(again.rc, 0) << again.output;
  EXPECT_EQ(again.output.find("is finished"), std::string::npos) << "a changed sequence was taken as finished";
  EXPECT_EQ(differingFiles(first, files(root)), "") << "the redone sequence is not the first one";
  EXPECT_EQ(viper::dataset::verifySequence(root, viper::dataset::readSequenceMarker(root + "/train/001.done")), "");

  // --force redoes a finished one.
  again = runGenerate(kRawBag, root, "--force --outputs layout");
  EXPECT_EQ(again.rc, 0) << again.output;
  EXPECT_FALSE(fs::exists(fs::path(root) / "train/bag/001.bag")) << "--outputs layout writes no bag";
}

// The marker takes the layout's checksums from the writers (the bytes they wrote, hashed as they
// went) and reads back only the bag: with writer threads and without, every checksum equals the
// SHA-256 of the file on disk (ours and sha256sum's). A resumed run still reads every file, so a
// file changed after the run, even to a byte of the same size, is found and the sequence redone.
TEST(Generate, MarkerChecksumsAsWrittenAreThoseOfTheFilesOnDisk) {
  for (const char* threads : {"2", "0"}) {
    SCOPED_TRACE(std::string("--writer-threads ") + threads);
    const std::string root = tempDir("viper_generate_") + "/as_written_" + threads;
    const Result r = runGenerate(kRawBag, root, std::string("--writer-threads ") + threads);
    ASSERT_EQ(r.rc, 0) << r.output;
    const viper::dataset::SequenceMarker m = viper::dataset::readSequenceMarker(root + "/train/001.done");
    ASSERT_GT(m.files.size(), 100u);
    EXPECT_NE(r.output.find("(checksums: 1 of " + std::to_string(m.files.size()) + " files read back)"), std::string::npos)
        << "only the bag is read back: " << r.output;
    for (const viper::dataset::MarkedFile& f : m.files)
      EXPECT_EQ(f.sha256, viper::dataset::sha256OfFile(fs::path(root) / f.relative_path)) << f.relative_path;
    EXPECT_EQ(run("cd " + root + " && sha256sum --quiet -c train/001.done"), 0);
    const auto first = files(root);

    // The same size, one byte changed: a flow file and the bag.
    for (const char* changed : {"train/flow/001/001_00005.npz", "train/bag/001.bag"}) {
      const fs::path file = fs::path(root) / changed;
      const std::string original = readFile(file.string());
      {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(original.size() / 2));
        f.put(static_cast<char>(original[original.size() / 2] ^ 0x20));
      }
      ASSERT_EQ(fs::file_size(file), original.size());
      ASSERT_TRUE(readFile(file.string()) != original) << changed << " could not be changed";
      const std::string why = viper::dataset::verifySequence(root, m);
      EXPECT_NE(why.find(changed), std::string::npos) << "verified: '" << why << "'";
      const Result again = runGenerate(kRawBag, root, std::string("--writer-threads ") + threads);
      EXPECT_EQ(again.rc, 0) << again.output;
      EXPECT_EQ(again.output.find("is finished"), std::string::npos) << changed << " changed, yet skipped";
      EXPECT_EQ(differingFiles(first, files(root)), "") << changed << " changed: the redone sequence is not the first one";
      EXPECT_EQ(viper::dataset::verifySequence(root, viper::dataset::readSequenceMarker(root + "/train/001.done")), "");
    }
  }
}

// Two generators given the same sequence at once (an array resubmitted while a task of the first
// still runs): one writes it, the other waits for it and finds it finished. Without the lock both
// would write the same temporary folder.
TEST(Generate, TwoGeneratorsOfOneSequenceTakeTurns) {
  const std::string dir = tempDir("viper_generate_"), root = dir + "/twice";
  const std::string one = std::string(VIPER_GENERATE) + " --input " + kRawBag + " --labels " + VIPER_WORLD_LABELS +
                          " --out " + root;
  ASSERT_EQ(run("(" + one + " > " + dir + "/a.log 2>&1; echo $? > " + dir + "/a.rc) & (" + one + " > " + dir +
                "/b.log 2>&1; echo $? > " + dir + "/b.rc) & wait"),
            0);
  const std::string a = readFile(dir + "/a.log"), b = readFile(dir + "/b.log");
  EXPECT_EQ(readFile(dir + "/a.rc"), "0\n") << a;
  EXPECT_EQ(readFile(dir + "/b.rc"), "0\n") << b;
  const bool a_skipped = a.find("is finished") != std::string::npos, b_skipped = b.find("is finished") != std::string::npos;
  EXPECT_NE(a_skipped, b_skipped) << "exactly one of them writes the sequence:\n" << a << "\n" << b;
  EXPECT_EQ(viper::dataset::verifySequence(root, viper::dataset::readSequenceMarker(root + "/train/001.done")), "");
  EXPECT_FALSE(fs::exists(root + "/.partial"));
  EXPECT_FALSE(fs::exists(viper::dataset::sequenceLockPath(root, "train", "001"))) << "the lock file is removed";
}

// While another process holds a sequence, generate says who and waits; then it writes the sequence.
TEST(Generate, WaitsForTheHolderOfTheSequenceLock) {
  const std::string dir = tempDir("viper_generate_"), root = dir + "/held";
  auto held = std::make_unique<viper::dataset::SequenceLock>(viper::dataset::sequenceLockPath(root, "train", "001"));
  const std::string log = dir + "/waiting.log";
  std::thread generator([&] {
    run(std::string(VIPER_GENERATE) + " --input " + kRawBag + " --labels " + VIPER_WORLD_LABELS + " --out " + root +
        " --outputs layout > " + log + " 2>&1; echo $? > " + dir + "/rc");
  });
  bool waiting = false;
  for (int i = 0; i < 600 && !waiting; ++i) {  // at most a minute
    waiting = readFile(log).find("is being generated by another process") != std::string::npos;
    if (!waiting) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(waiting) << readFile(log);
  EXPECT_NE(readFile(log).find("pid " + std::to_string(::getpid())), std::string::npos) << "names the holder: "
                                                                                          << readFile(log);
  EXPECT_FALSE(fs::exists(root + "/train")) << "nothing written while the lock is held";
  held.reset();
  generator.join();
  EXPECT_EQ(readFile(dir + "/rc"), "0\n") << readFile(log);
  EXPECT_TRUE(fs::exists(root + "/train/001.done")) << readFile(log);
}

TEST(Generate, DamagedCaptureKeepsItsIntactFrames) {
  // The first 2 MiB of the capture: a truncated stream whose earlier frames are intact.
  const std::string truncated = tempDir("viper_generate_") + "/truncated.vcap";
  {
    const std::string bytes = readFile(kCapture);
    ASSERT_GT(bytes.size(), 3u << 20);
    std::ofstream(truncated, std::ios::binary).write(bytes.data(), 2 << 20);
  }
  const std::string root = tempDir("viper_generate_") + "/damaged";
  const Result r = runGenerate(truncated, root);
  EXPECT_EQ(r.rc, 1) << r.output;
  EXPECT_NE(r.output.find("is damaged at byte"), std::string::npos) << r.output;
  const viper::dataset::SequenceMarker m = viper::dataset::readSequenceMarker(root + "/train/001.done");
  EXPECT_GT(m.frames, 0u);
  EXPECT_LT(m.frames, 20u);
  char last[32];
  std::snprintf(last, sizeof last, "001_%05llu.png", static_cast<unsigned long long>(m.frames - 1));
  EXPECT_TRUE(fs::exists(fs::path(root) / "train/img/001" / last)) << last;
}

TEST(Generate, UnwritableOutputIsAnErrorWithoutMarker) {
  const std::string root = tempDir("viper_generate_") + "/not_a_folder";
  std::ofstream(root) << "a file where the dataset should go";
  const Result r = runGenerate(kRawBag, root);
  EXPECT_EQ(r.rc, 2) << r.output;
  EXPECT_NE(r.output.find(root), std::string::npos) << "the error names the path: " << r.output;
  EXPECT_FALSE(fs::exists(root + "/train/001.done"));

  const Result usage = runGenerate("", root);
  EXPECT_EQ(usage.rc, 2);
  EXPECT_NE(usage.output.find("usage: generate"), std::string::npos);
}

// A full disk, as a file-size limit (ulimit -f, SIGXFSZ ignored: writes fail with EFBIG as they
// would with ENOSPC): an error naming the file that could not be written, exit 2, no marker, and
// what was written before it stays in the partial sequence.
TEST(Generate, FullDiskIsAnErrorNamingTheFile) {
  struct Case {
    const char* outputs;
    int limit_kib;
    const char* file;  // what fails first
    const char* root;
  };
  for (const Case& c : {Case{"layout,bag", 4096, "/train/bag/001.bag: cannot write bag", "/full_bag"},
                        Case{"layout", 100, "/train/img/001/001_00000.png: cannot write PNG", "/full_layout"}}) {
    const std::string root = tempDir("viper_generate_") + c.root;
    const std::string log = root + ".log";
    const int rc = run("sh -c \"trap '' XFSZ; ulimit -f " + std::to_string(c.limit_kib) + "; exec " + VIPER_GENERATE +
                       " --input " + kRawBag + " --labels " + VIPER_WORLD_LABELS + " --out " + root + " --outputs " +
                       c.outputs + "\" > " + log + " 2>&1");
    const std::string out = readFile(log);
    EXPECT_EQ(rc, 2) << c.outputs << ": " << out;
    EXPECT_NE(out.find(root + "/.partial/train_001" + c.file), std::string::npos) << c.outputs << ": " << out;
    EXPECT_NE(out.find("File too large"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(root + "/train/001.done")) << c.outputs;
  }
  // The bag fills up after some frames: their layout files were written whole before it.
  const std::string partial = tempDir("viper_generate_") + "/full_bag/.partial/train_001/train/img/001/001_00000.png";
  EXPECT_TRUE(fs::exists(partial));
  EXPECT_EQ(readFile(partial).rfind("IEND"), readFile(partial).size() - 8) << "a whole PNG";
}

}  // namespace
