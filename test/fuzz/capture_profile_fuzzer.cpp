// libFuzzer target: arbitrary text as a capture profile (YAML). It must parse or end in
// std::runtime_error naming the source; a parsed profile must answer match() for any program.
// Seeds: the profiles the package ships (config/profiles).
#include "fuzz_support.h"
#include "viper/capture/capture_profile.h"

#include <filesystem>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(VIPER_ROOT "/config/profiles"))
    std::filesystem::copy_file(entry.path(), dir + "/" + entry.path().filename().string(),
                               std::filesystem::copy_options::overwrite_existing);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const viper::CaptureProfile profile = viper::parseCaptureProfile(text, "fuzz-input");
    if (profile.match("uniform mat4 bones[8]; void main() {}", 0x1234) == nullptr) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
