// Programs the package was not written for (docs/program_corpus.md), the fast ones: each traced
// unattended, replayed plainly and under `capture`, its image compared frame by frame within its
// known differences, the capture checked against itself (scripts/capture_corpus.sh, whose exit
// status says whether every program's image and capture held). Then what the layer gets out of
// each today, as the reference page says: ids on every pixel glmark2 draws, and Neverball (fixed
// function, its matrix stack) with ids, placement and reprojection all but complete.
#include "../common/process_util.h"
#include "../common/sanitized_build.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

constexpr const char* kSanitizedSkip = "the layer run would carry the sanitizer's runtime and the plain run not";

// The script's fast programs (each under a minute, trace and three replays, on two cores).
const std::vector<std::string> kPrograms = {"glmark2", "neverball", "supertux", "chromium-bsu", "extremetuxracer",
                                            "glxgears"};

// One row of the script's table: program frames undef identical% within1% max ids% placed% time check...
struct Row {
  int frames = 0;
  double identical = 0, within_one = 0, ids = 0, placed = 0;
  std::string check;
};

}  // namespace

TEST(Corpus, FastProgramsRunUnchangedUnderTheLayer) {
  VIPER_SKIP_IN_SANITIZED_BUILD(kSanitizedSkip);
  const std::string dir = viper::test::tempDir("viper_corpus_");
  const std::string bin = fs::path(VIPER_CAPTURE_EXE).parent_path().string();
  std::string command = "scripts/capture_corpus.sh --out " + dir + "/run --bin " + bin;
  for (const std::string& p : kPrograms) command += " --program " + p;
  const std::string log = dir + "/corpus.log";
  const int rc = viper::test::run(command + " > " + log + " 2>&1");
  const std::string text = viper::test::readFile(log);
  ASSERT_NE(rc, 2) << "a program or a tool is missing (scripts/setup.sh --test-programs):\n" << text;
  EXPECT_EQ(rc, 0) << "an image beyond its known differences, a replay that failed under capture, or a failed "
                      "check:\n"
                   << text;

  std::map<std::string, Row> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream in(line);
    std::string name, max, time;
    int undef = 0;
    Row r;
    if (!(in >> name >> r.frames >> undef >> r.identical >> r.within_one >> max >> r.ids >> r.placed >> time)) continue;
    std::getline(in, r.check);
    r.check = r.check.substr(r.check.find_first_not_of(' '));
    rows[name] = r;
  }
  for (const std::string& p : kPrograms) {
    SCOPED_TRACE(p);
    ASSERT_TRUE(rows.count(p)) << "no row for it:\n" << text;
    EXPECT_GT(rows[p].frames, 50);
  }
  EXPECT_GE(rows["glmark2"].ids, 99.0) << text;
  EXPECT_GE(rows["neverball"].ids, 99.0) << text;
  EXPECT_GE(rows["neverball"].placed, 99.0) << text;
  EXPECT_EQ(rows["neverball"].check.rfind("met", 0), 0u) << rows["neverball"].check;
  if (!HasFailure() && !std::getenv("VIPER_KEEP_RUN"))
    fs::remove_all(dir);
  else
    std::printf("the corpus run is kept in %s\n", dir.c_str());
}
