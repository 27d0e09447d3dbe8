// The house rule of docs/design.md, "Stages depend downwards only" (capture <- ground truth <-
// evaluation, dataset; the report's plots under the last two), held against the code: every #include of the core's stages and of the
// capture layers, and the libraries the layers load into a foreign program.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = VIPER_SOURCE_DIR;

// The stage a header belongs to, from its include path ("viper/ground_truth/boxes.h", or a
// relative "../ground_truth/x86_kernels.h" from a file in `from`); "" for one outside the stages.
std::string stageOfInclude(const std::string& include, const fs::path& from) {
  static const std::regex viper("^viper/([a-z_]+)/");
  std::smatch m;
  if (std::regex_search(include, m, viper)) return m[1];
  if (include.rfind("../", 0) != 0) return "";
  const fs::path resolved = (from.parent_path() / include).lexically_normal();
  const fs::path relative = resolved.lexically_relative(kSource / "src");
  return relative.empty() || *relative.begin() == ".." ? "" : relative.begin()->string();
}

struct Violation {
  std::string file, include;
};

// Every #include "..." of the files under `folders` whose stage is one of `forbidden`.
std::vector<Violation> includesOf(const std::vector<std::string>& folders, const std::set<std::string>& forbidden) {
  static const std::regex line("^\\s*#\\s*include\\s+\"([^\"]+)\"");
  std::vector<Violation> found;
  for (const std::string& folder : folders) {
    const fs::path root = kSource / folder;
    if (!fs::exists(root)) continue;
    for (const auto& e : fs::recursive_directory_iterator(root)) {
      if (!e.is_regular_file()) continue;
      const std::string ext = e.path().extension().string();
      if (ext != ".h" && ext != ".cpp" && ext != ".hpp") continue;
      std::ifstream in(e.path());
      std::string text;
      while (std::getline(in, text)) {
        std::smatch m;
        if (!std::regex_search(text, m, line)) continue;
        if (forbidden.count(stageOfInclude(m[1], e.path())))
          found.push_back({e.path().lexically_relative(kSource).string(), m[1]});
      }
    }
  }
  return found;
}

std::string describe(const std::vector<Violation>& v) {
  std::string out;
  for (const Violation& x : v) out += "\n  " + x.file + " includes " + x.include;
  return out;
}

TEST(StageDependencies, CaptureIncludesNoLaterStage) {
  const auto v = includesOf({"src/capture", "include/viper/capture"}, {"ground_truth", "evaluation", "dataset", "ros"});
  EXPECT_TRUE(v.empty()) << "the capture stage reaches up:" << describe(v);
}

TEST(StageDependencies, GroundTruthIncludesNeitherEvaluationNorDataset) {
  const auto v = includesOf({"src/ground_truth", "include/viper/ground_truth"}, {"evaluation", "dataset", "ros"});
  EXPECT_TRUE(v.empty()) << "the ground-truth stage reaches up:" << describe(v);
}

TEST(StageDependencies, EvaluationAndDatasetDoNotIncludeEachOther) {
  const auto e = includesOf({"src/evaluation", "include/viper/evaluation"}, {"dataset", "ros"});
  EXPECT_TRUE(e.empty()) << "evaluation reaches into dataset or ROS:" << describe(e);
  const auto d = includesOf({"src/dataset", "include/viper/dataset"}, {"evaluation", "ros"});
  EXPECT_TRUE(d.empty()) << "dataset reaches into evaluation or ROS:" << describe(d);
}

// Line plots and CSV numbers (include/viper/report) sit under evaluation and dataset, which both
// use them: they include no stage.
TEST(StageDependencies, ReportIncludesNoStage) {
  const auto v = includesOf({"src/report", "include/viper/report"}, {"capture", "ground_truth", "evaluation", "dataset", "ros"});
  EXPECT_TRUE(v.empty()) << "the report's plots reach into a stage:" << describe(v);
}

// The libraries a capture layer makes the program load: of the package's own, only the capture
// stage's (not the ground truth, metrics and dataset code it has no use for).
std::set<std::string> neededLibraries(const fs::path& library) {
  std::set<std::string> needed;
  const std::string command = "readelf -d '" + library.string() + "' 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return needed;
  static const std::regex entry("\\(NEEDED\\).*\\[([^\\]]+)\\]");
  char buffer[512];
  while (fgets(buffer, sizeof buffer, pipe.get())) {
    std::cmatch m;
    if (std::regex_search(buffer, m, entry)) needed.insert(m[1]);
  }
  return needed;
}

TEST(StageDependencies, CaptureLayersLoadOnlyTheCaptureStage) {
  for (const char* layer : {VIPER_INTERCEPT_LIB, VIPER_VULKAN_LAYER_LIB}) {
    SCOPED_TRACE(layer);
    const std::set<std::string> needed = neededLibraries(layer);
    ASSERT_FALSE(needed.empty()) << "readelf -d read nothing of " << layer;
    EXPECT_TRUE(needed.count("libviper_capture_core.so")) << "the layer does not link the capture stage";
    for (const std::string& lib : needed) {
      if (lib.rfind("libviper_", 0) == 0) {
        EXPECT_EQ(lib, "libviper_capture_core.so") << "the layer loads " << lib;
      }
    }
  }
}

}  // namespace
