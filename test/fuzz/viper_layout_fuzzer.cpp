// libFuzzer target: an arbitrary file name as a frame file of VIPER's layout
// (`<seq>_<frame>.<extension>`), which scanViperSequence parses for every file of a folder. A name
// parses or is refused (nullopt); a parsed name has a seq without '_' and formats back through
// viperFramePath to a path that parses to the same parts.
// Seeds: names viperFramePath makes (5 digits, more digits, every extension of the layout).
#include "fuzz_support.h"
#include "viper/dataset/viper_layout.h"

#include <string>

namespace {

std::string fileName(const std::string& path) { return path.substr(path.rfind('/') + 1); }

}  // namespace

void viper::fuzz::writeSeeds(const std::string& dir) {
  using viper::dataset::viperFramePath;
  int n = 0;
  for (const char* ext : {"png", "jpg", "npz", "csv"})
    writeBytes(dir + "/name" + std::to_string(n++), fileName(viperFramePath("", "train", "img", "001", 42, ext)));
  writeBytes(dir + "/name" + std::to_string(n++), fileName(viperFramePath("", "val", "flow", "077", 1234567, "npz")));
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string name(reinterpret_cast<const char*>(data), size);
  const auto parsed = viper::dataset::parseViperFrameName(name);
  if (!parsed) return 0;
  if (parsed->seq.empty() || parsed->seq.find('_') != std::string::npos) __builtin_trap();
  const std::string path =
      viper::dataset::viperFramePath("", "s", "m", parsed->seq, parsed->frame, parsed->extension);
  const auto again = viper::dataset::parseViperFrameName(fileName(path));
  if (!again || again->seq != parsed->seq || again->frame != parsed->frame || again->extension != parsed->extension)
    __builtin_trap();
  return 0;
}
