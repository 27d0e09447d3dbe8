// Helpers of the tests of the flow file formats: a flow image of a given size, and reading a damaged
// flow file.
#pragma once

#include "viper/dataset/flow_image.h"

#include "dataset_test_util.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace viper_dataset_test {

/// A width x height flow image, every value 0.
inline viper::dataset::FlowImage zeroFlow(uint32_t width, uint32_t height) {
  viper::dataset::FlowImage f;
  f.width = width;
  f.height = height;
  f.uv.resize(2 * f.pixels());
  return f;
}

/// Writes `bytes`, a damaged flow file, at `path` and reads it with `read`: a flow with two values a
/// pixel, or a std::runtime_error that names the file. Returns whether it was an error.
inline bool readsOrNamesTheFile(const std::string& path, const std::vector<uint8_t>& bytes,
                                const std::function<viper::dataset::FlowImage(const std::string&)>& read) {
  writeBytes(path, bytes);
  try {
    const viper::dataset::FlowImage f = read(path);
    EXPECT_EQ(f.uv.size(), 2 * f.pixels());
    return false;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    return true;
  }
}

}  // namespace viper_dataset_test
