#include "fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <stdexcept>

namespace viper::fuzz {
namespace {

std::set<std::string>& scratchPaths() {
  static std::set<std::string> paths;
  return paths;
}

void removeScratchFiles() {
  for (const std::string& path : scratchPaths()) std::remove(path.c_str());
}

std::string scratchFolder() {
  if (const char* tmp = std::getenv("TMPDIR")) return tmp;
  return access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
}

}  // namespace

std::string scratchFile(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path = scratchFolder() + "/viper_fuzz_" + std::to_string(getpid()) + suffix;
  if (scratchPaths().empty()) std::atexit(removeScratchFiles);
  scratchPaths().insert(path);
  writeBytes(path, std::string(reinterpret_cast<const char*>(data), size));
  return path;
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write");
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  writeBytes(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace viper::fuzz

// libFuzzer calls this once before fuzzing; in seed mode the binary writes its seeds and exits.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* dir = std::getenv("VIPER_FUZZ_SEEDS");
  if (dir == nullptr) return 0;
  try {
    viper::fuzz::writeSeeds(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "writing seeds into %s failed: %s\n", dir, e.what());
    std::exit(1);
  }
  std::exit(0);
}
