// Every `rosrun viper NAME` that README.md, docs/commands.md and docs/nodes.md write runs as written:
// rosrun finds NAME (a devel space inside the package's build/ is skipped by rosrun, and folders
// named like a command are not it), and the command-line tools among them answer --help with their
// usage and exit code 0. ROS nodes (lines that pass _param:= or __ns:=) are only looked up
// (rosrun --prefix true), not started. Runs with the devel space sourced (scripts/test.sh).
#include "../common/process_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <regex>
#include <sstream>
#include <string>

namespace {

struct Documented {
  bool node = false;  // some line passes it ROS parameters
};

// The pages whose commands users copy: the front door and the two references.
const char* const kPages[] = {"README.md", "docs/commands.md", "docs/nodes.md"};

// Adds the commands `text` writes to `out`.
void documentedCommands(const std::string& text, std::map<std::string, Documented>& out) {
  const std::regex command(R"(rosrun viper ([A-Za-z0-9_]+)([^`|\n]*))");
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
    for (std::sregex_iterator it(line.begin(), line.end(), command), end; it != end; ++it) {
      const std::string args = (*it)[2];
      Documented& d = out[(*it)[1]];
      d.node = d.node || args.find(":=") != std::string::npos;
    }
}

// Output (stdout and stderr) and exit status of a shell command.
std::pair<int, std::string> capture(const std::string& command) {
  std::string out;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return {-1, out};
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace

TEST(ReadmeCommands, EveryRosrunCommandIsFoundAndToolsAnswerHelp) {
  std::map<std::string, Documented> commands;
  for (const char* page : kPages) {
    SCOPED_TRACE(page);
    const std::string text = viper::test::readFile(std::string(VIPER_SOURCE_DIR "/") + page);
    ASSERT_FALSE(text.empty());
    std::map<std::string, Documented> on_page;
    documentedCommands(text, on_page);
    EXPECT_FALSE(on_page.empty()) << page << " writes no `rosrun viper` command";
    documentedCommands(text, commands);
  }
  ASSERT_GE(commands.size(), 25u) << "README.md and docs/ document the package's commands with rosrun";
  size_t tools = 0;
  for (const auto& [name, doc] : commands) {
    SCOPED_TRACE(name);
    const auto [found_rc, found_out] = capture("rosrun --prefix true viper " + name);
    EXPECT_EQ(found_rc, 0) << "rosrun does not find it:\n" << found_out;
    if (doc.node) continue;
    ++tools;
    const auto [rc, out] = capture("timeout 60 rosrun viper " + name + " --help");
    std::string lower = out;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(lower.find("usage"), std::string::npos) << out;
    EXPECT_EQ(out.find("[rosrun]"), std::string::npos) << out;
  }
  EXPECT_GE(tools, 10u);
}
