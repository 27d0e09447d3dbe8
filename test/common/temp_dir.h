// A temporary folder of one test or fixture, gone with everything in it when the test is done
// (process_util.h's tempDir() is the one folder a whole test binary shares).
#pragma once

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace viper {
namespace test {

/// A fresh folder <system temporary folder>/<prefix>XXXXXX, made by the constructor (which throws
/// std::runtime_error if it cannot) and removed with everything in it by the destructor.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "viper_test_") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
    if (mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("cannot make " + pattern + ": " + std::strerror(errno));
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` in the folder.
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace test
}  // namespace viper
