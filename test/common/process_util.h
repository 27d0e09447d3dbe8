// Helpers of the tests that run programs: a shell command's exit status, a file's bytes, and one
// temporary folder per test binary.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace viper {
namespace test {

/// Exit status of a shell command (-1 if it did not exit normally).
inline int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// "env LD_PRELOAD=<runtime> " (a command prefix) when this test binary runs with a sanitizer's
/// runtime (a build by scripts/sanitize.sh), else "": for a program the test compares with a run
/// under `capture`, which preloads that runtime for the sanitized layer, so that both run with the
/// same allocator (ASan fills new heap memory: a program that reads memory it never wrote draws
/// otherwise).
inline std::string sanitizerPreload() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    const size_t slash = line.find('/');
    if (slash == std::string::npos) continue;
    const std::string path = line.substr(slash);
    const std::string base = path.substr(path.rfind('/') + 1);
    if (base.rfind("libasan.so", 0) == 0 || base.rfind("libtsan.so", 0) == 0) return "env LD_PRELOAD=" + path + " ";
  }
  return "";
}

/// A file's whole contents (empty if it cannot be read).
inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// /tmp/<prefix>XXXXXX, made on the first call; the same folder on every later call.
inline std::string tempDir(const char* prefix = "viper_test_") {
  static const std::string dir = [prefix] {
    std::string pattern = std::string("/tmp/") + prefix + "XXXXXX";
    return std::string(mkdtemp(pattern.data()));
  }();
  return dir;
}

}  // namespace test
}  // namespace viper
