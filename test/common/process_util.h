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
