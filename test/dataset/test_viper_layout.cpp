// File names of VIPER's release layout.
#include "viper/dataset/viper_layout.h"

#include <gtest/gtest.h>

namespace {

using namespace viper::dataset;

TEST(ViperLayout, BuildsReleasePaths) {
  EXPECT_EQ(viperFramePath("/data/viper", "train", "flow", "001", 10, "npz"), "/data/viper/train/flow/001/001_00010.npz");
  EXPECT_EQ(viperFramePath("", "val", "flowbw", "077", 0, "npz"), "val/flowbw/077/077_00000.npz");
  EXPECT_EQ(viperFramePath("out/", "test", "img", "a", 99999, "jpg"), "out/test/img/a/a_99999.jpg");
  EXPECT_EQ(viperFramePath("r", "train", "flow", "001", 123456, "flo"), "r/train/flow/001/001_123456.flo");
}

TEST(ViperLayout, RejectsNamesThatBreakTheLayout) {
  EXPECT_THROW(viperFramePath("r", "", "flow", "001", 0, "npz"), std::invalid_argument);
  EXPECT_THROW(viperFramePath("r", "train/x", "flow", "001", 0, "npz"), std::invalid_argument);
  EXPECT_THROW(viperFramePath("r", "train", "", "001", 0, "npz"), std::invalid_argument);
  EXPECT_THROW(viperFramePath("r", "train", "flow", "my_seq", 0, "npz"), std::invalid_argument);
  EXPECT_THROW(viperFramePath("r", "train", "flow", "", 0, "npz"), std::invalid_argument);
  EXPECT_THROW(viperFramePath("r", "train", "flow", "001", 0, ""), std::invalid_argument);
}

TEST(ViperLayout, ParsesWhatItBuilds) {
  for (uint64_t frame : {0ull, 7ull, 12345ull, 1234567ull}) {
    const std::string path = viperFramePath("", "train", "flow", "042", frame, "npz");
    const auto parsed = parseViperFrameName(path.substr(path.rfind('/') + 1));
    ASSERT_TRUE(parsed.has_value()) << path;
    EXPECT_EQ(parsed->seq, "042");
    EXPECT_EQ(parsed->frame, frame);
    EXPECT_EQ(parsed->extension, "npz");
  }
  const auto jpg = parseViperFrameName("001_00010.jpg");
  ASSERT_TRUE(jpg.has_value());
  EXPECT_EQ(jpg->frame, 10u);
  for (const char* bad : {"00100010.jpg", "_00010.jpg", "001_.jpg", "001_00010", "001_00010.", "001_0a010.jpg",
                          "a/001_00010.jpg", "001_99999999999999999999.npz"})
    EXPECT_FALSE(parseViperFrameName(bad).has_value()) << bad;
}

}  // namespace
