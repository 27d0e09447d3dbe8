// libFuzzer target: an arbitrary file as the VIPER class table (CSV). It must load or end in
// std::runtime_error naming the file and line; a loaded table holds ids 0..n-1 in order.
// Seeds: the package's config/viper_classes.csv and its first rows.
#include "fuzz_support.h"
#include "viper/ground_truth/class_table.h"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

void viper::fuzz::writeSeeds(const std::string& dir) {
  std::ifstream in(VIPER_ROOT "/config/viper_classes.csv");
  std::stringstream all;
  all << in.rdbuf();
  writeBytes(dir + "/viper_classes.csv", all.str());
  std::string head, line;
  all.seekg(0);
  for (int i = 0; i < 3 && std::getline(all, line); ++i) head += line + "\r\n";
  writeBytes(dir + "/first_rows.csv", head);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = viper::fuzz::scratchFile(data, size, ".csv");
  try {
    const viper::ClassTable table = viper::ClassTable::load(path);
    for (size_t id = 0; id < table.size(); ++id)
      if (table.at(static_cast<int>(id)).id != static_cast<int>(id) || table.idOf(table.at(int(id)).name) < 0)
        __builtin_trap();
    if (table.semanticEvalMask().size() != table.size()) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
