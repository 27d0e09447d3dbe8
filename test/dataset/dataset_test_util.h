// Helpers of the dataset tests: a temporary folder, whole-file IO, and checking that an error
// names what it should.
#pragma once

#include "../common/temp_dir.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

namespace viper_dataset_test {

/// A fresh folder viper_dataset_XXXXXX under the system's temporary folder, removed with everything in it.
struct TempDir : viper::test::TempDir {
  TempDir() : viper::test::TempDir("viper_dataset_") {}
};

/// Runs `command` in a shell, stdin from /dev/null; returns its exit code (-1 if it did not exit),
/// its stdout and stderr appended to `out`.
inline int runCommand(const std::string& command, std::string& out) {
  FILE* p = popen((command + " 2>&1 < /dev/null").c_str(), "r");
  if (p == nullptr) return -1;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, p)) > 0) out.append(buffer, n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

/// Runs `f`, expecting a std::runtime_error whose message holds every one of `parts`.
inline void expectErrorNaming(const std::function<void()>& f, std::initializer_list<std::string> parts,
                              const std::string& context) {
  try {
    f();
    ADD_FAILURE() << context << ": no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    for (const auto& p : parts) EXPECT_NE(what.find(p), std::string::npos) << context << ": '" << what << "' lacks '" << p << "'";
  }
}

}  // namespace viper_dataset_test
