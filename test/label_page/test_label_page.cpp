// The labelling page in a real headless browser: the GL test program captured, label_resources
// writes its page, label_page.js (Playwright driving Debian's Chromium) picks a class per resource
// as a person would and saves; the saved table must hold exactly what was picked, load as a label
// table, and label the capture's draws with it. Then the same with "Take the proposals".
#include "../common/process_util.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/label_table.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace {

using viper::test::readFile;
using viper::test::run;
std::string tempDir() { return viper::test::tempDir("viper_label_page_"); }

struct Page {
  std::string dir;
  std::vector<viper::CaptureFrame> frames;
  std::set<uint64_t> mesh_keys;
};

// The GL test program's scene (test_scene_layout.h) captured and its page written.
const Page& page() {
  static Page p = [] {
    Page page;
    const std::string d = tempDir();
    page.dir = d + "/page";
    EXPECT_EQ(run(std::string(VIPER_CAPTURE_EXE) + " --output " + d + "/scene.vcap --profile " VIPER_PROFILE_DIR
                  "/viper_scene.yaml -- " VIPER_GL_TEST_PROGRAM " --frames 3 --size 160x120 > /dev/null"),
              0);
    EXPECT_EQ(run(std::string(VIPER_LABEL_RESOURCES) + " " + d + "/scene.vcap --out " + page.dir + " > /dev/null"), 0);
    viper::CaptureReader reader(d + "/scene.vcap");
    viper::CaptureFrame f;
    while (reader.next(f) == viper::CaptureReader::Status::kFrame) {
      for (const auto& draw : f.draws)
        if (draw.mesh_key && draw.visible_pixels) page.mesh_keys.insert(draw.mesh_key);
      page.frames.push_back(f);
    }
    return page;
  }();
  return p;
}

std::string driver() {
  return "cd " VIPER_LABEL_PAGE_TEST_DIR " && node label_page.js ";
}

}  // namespace

TEST(LabelPage, SavedTableIsWhatWasPicked) {
  for (const char* tool : {"/usr/bin/chromium", "/usr/bin/node"})
    ASSERT_TRUE(fs::exists(tool)) << tool << " is missing: run 'bash scripts/setup.sh --test-programs'";
  ASSERT_TRUE(fs::exists(VIPER_LABEL_PAGE_TEST_DIR "/node_modules/playwright-core"))
      << "playwright-core is missing: run 'bash scripts/setup.sh --test-programs'";
  const Page& p = page();
  ASSERT_TRUE(fs::exists(p.dir + "/index.html"));
  ASSERT_EQ(p.mesh_keys.size(), 3u) << "quad, triangle, skinned strip (the glass, a blended effect, takes no pixel)";
  // A different class for each mesh, as a person would pick them in its row.
  std::map<uint64_t, int> picked;
  const int classes[3] = {24, 9, 7};
  std::ostringstream json;
  json << "{";
  int i = 0;
  for (uint64_t key : p.mesh_keys) {
    picked[key] = classes[i];
    json << (i ? ", " : "") << "\"mesh:" << viper::keyToHex(key) << "\": " << classes[i];
    ++i;
  }
  json << "}";
  const std::string choices = tempDir() + "/choices.json", saved = tempDir() + "/picked.yaml";
  std::ofstream(choices) << json.str();
  ASSERT_EQ(run(driver() + p.dir + " " + choices + " " + saved + " --screenshot " + tempDir() + "/page.png"), 0);

  const std::string text = readFile(saved);
  const viper::LabelTable table = viper::LabelTable::load(saved);
  EXPECT_EQ(table.size(), picked.size()) << text;
  for (const auto& [key, id] : picked) {
    EXPECT_NE(text.find("\"" + viper::keyToHex(key) + "\": " + std::to_string(id)), std::string::npos) << text;
    viper::DrawRecord probe;
    probe.mesh_key = key;
    EXPECT_EQ(table.classOf(probe), id);
  }
  // The capture's draws take their labels from it.
  for (const auto& draw : p.frames.back().draws)
    if (draw.mesh_key && picked.count(draw.mesh_key)) {
      EXPECT_EQ(table.classOf(draw), picked.at(draw.mesh_key));
    }

  // A row that does not exist is an error, not a silent skip.
  std::ofstream(tempDir() + "/bad.json") << "{\"mesh:0123456789abcdef\": 3}";
  EXPECT_EQ(run(driver() + p.dir + " " + tempDir() + "/bad.json " + tempDir() + "/bad.yaml 2> /dev/null"), 1);
}

TEST(LabelPage, TakingTheProposalsKeepsWhatWasPicked) {
  const Page& p = page();
  ASSERT_FALSE(p.mesh_keys.empty());
  // One pick; the rest from the page's proposals (the skinned strip is proposed "person").
  const uint64_t first = *p.mesh_keys.begin();
  const std::string choices = tempDir() + "/one.json", saved = tempDir() + "/proposals.yaml";
  std::ofstream(choices) << "{\"mesh:" << viper::keyToHex(first) << "\": 11}";
  ASSERT_EQ(run(driver() + p.dir + " " + choices + " " + saved + " --take-proposals"), 0);
  const viper::LabelTable table = viper::LabelTable::load(saved);
  viper::DrawRecord probe;
  probe.mesh_key = first;
  EXPECT_EQ(table.classOf(probe), 11) << "a pick is not replaced by a proposal";
  bool skinned_is_person = false;
  for (const auto& draw : p.frames.back().draws)
    if (!draw.deformed_clip_xyzw.empty() && draw.mesh_key != first) skinned_is_person = table.classOf(draw) == 20;
  EXPECT_TRUE(skinned_is_person) << readFile(saved);
}
