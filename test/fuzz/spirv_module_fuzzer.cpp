// libFuzzer target: arbitrary bytes as a SPIR-V module, what the Vulkan capture layer reads from
// every shader a program creates. reflectModule must report bad input (valid false, a problem) and
// never read outside the words; addIdOutput must refuse with a reason, or give a module that
// SPIRV-Tools validates (it validates before returning) and that reads back with the same entry
// points. Seeds: vk_test_scene's shaders, compiled by glslangValidator as the build does.
#include "fuzz_support.h"
#include "src/capture/vulkan/spirv_module.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

void viper::fuzz::writeSeeds(const std::string& dir) {
  const std::string shaders = VIPER_ROOT "/scene/vulkan/shaders";
  for (const auto& entry : std::filesystem::directory_iterator(shaders)) {
    const std::string name = entry.path().filename().string();
    for (const char* define : {"", "-DSKINNED"}) {
      if (*define && name != "scene.vert") continue;
      const std::string out = dir + "/" + name + (*define ? ".skinned" : "") + ".spv";
      const std::string command = "glslangValidator -V --target-env vulkan1.2 " + std::string(define) + " -o " + out +
                                  " " + entry.path().string() + " > /dev/null";
      if (std::system(command.c_str()) != 0) std::remove(out.c_str());
    }
  }
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint32_t> words(size / 4);
  if (!words.empty()) std::memcpy(words.data(), data, words.size() * 4);
  const viper::capture::vulkan::ModuleReflection r = viper::capture::vulkan::reflectModule(words);
  if (!r.valid && r.problem.empty()) __builtin_trap();
  for (const viper::capture::vulkan::IdOutput id : {viper::capture::vulkan::IdOutput{1, 80, -1},
                                                    viper::capture::vulkan::IdOutput{2, 0, 7}}) {
    std::string why;
    const std::vector<uint32_t> out = viper::capture::vulkan::addIdOutput(words, "main", id, why);
    if (out.empty()) {
      if (why.empty()) __builtin_trap();
      continue;
    }
    const viper::capture::vulkan::ModuleReflection after = viper::capture::vulkan::reflectModule(out);
    if (!after.valid || after.entry_points != r.entry_points) __builtin_trap();
  }
  return 0;
}
