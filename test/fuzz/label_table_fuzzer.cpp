// libFuzzer target: an arbitrary file as a resource label table (YAML). It must load or end in
// std::runtime_error naming the file; a loaded table must label any draw.
// Seeds: a table written by LabelTable::save, and the tables the package ships (config/labels).
#include "fuzz_support.h"
#include "viper/ground_truth/label_table.h"

#include <filesystem>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  viper::LabelTable table;
  table.setMesh(0x8f3a0c1d22e4b7a9ull, 24);
  table.setTexture(0x0123456789abcdefull, 9);
  table.setProgram(0xfedcba9876543210ull, 2);
  table.save(dir + "/saved.yaml");
  viper::LabelTable().save(dir + "/empty.yaml");
  for (const auto& entry : std::filesystem::directory_iterator(VIPER_ROOT "/config/labels"))
    std::filesystem::copy_file(entry.path(), dir + "/" + entry.path().filename().string(),
                               std::filesystem::copy_options::overwrite_existing);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".yaml");
  try {
    const viper::LabelTable table = viper::LabelTable::load(path);
    viper::DrawRecord draw;
    draw.mesh_key = 0x8f3a0c1d22e4b7a9ull;
    draw.texture_keys = {0x0123456789abcdefull};
    (void)table.classOf(draw);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
