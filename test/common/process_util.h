// Helpers of the tests that run programs: a shell command's exit status, a file's bytes, and one
// temporary folder per test binary, removed when it exits.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
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

/// /tmp/<prefix>XXXXXX, made on the first call; the same folder on every later call. It goes, with
/// everything in it, when the test binary exits (a full suite would otherwise leave gigabytes in
/// /tmp: a wine prefix, SuperTuxKart's captures, generated sequences; on a small disk the later
/// tests then fail for want of space). VIPER_KEEP_TEST_FILES=1 keeps it, to look at after a failure.
inline std::string tempDir(const char* prefix = "viper_test_") {
  struct Folder {
    std::string path;
    pid_t owner = ::getpid();  // a forked child that exits does not take the parent's folder
    ~Folder() {
      const char* keep = std::getenv("VIPER_KEEP_TEST_FILES");
      if (path.empty() || ::getpid() != owner || (keep && *keep && std::string(keep) != "0")) return;
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Folder dir{[prefix] {
    std::string pattern = std::string("/tmp/") + prefix + "XXXXXX";
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot make " + pattern + ": " + std::strerror(errno));
    return pattern;
  }()};
  return dir.path;
}

}  // namespace test
}  // namespace viper
