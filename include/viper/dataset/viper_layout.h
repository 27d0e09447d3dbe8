// File names of VIPER's release layout: <root>/<split>/<modality>/<seq>/<seq>_<frame>.<ext>, e.g.
// train/flow/001/001_00010.npz. Splits are "train", "val", "test"; modalities "img", "cls",
// "inst", "flow" (forward flow), "flowbw" (backward flow), "bb", "camera". Sequence names are
// digits in the release ("001"); frame numbers are zero-padded to 5 digits.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace viper::dataset {

/// `<root>/<split>/<modality>/<seq>/<seq>_<frame:05d>.<extension>`; `root` may be empty (a
/// relative path results); `extension` is given without its dot ("npz"). Frame numbers beyond
/// 99999 get more digits. Throws std::invalid_argument if split, modality, seq or extension is
/// empty or holds '/', or if seq holds '_' (VIPER's tools split file names at the first '_').
std::string viperFramePath(const std::string& root, const std::string& split,
                           const std::string& modality, const std::string& seq, uint64_t frame,
                           const std::string& extension);

/// The parts of a VIPER frame file name.
struct ViperFrameName {
  std::string seq;
  uint64_t frame = 0;
  std::string extension;  ///< without its dot
};

/// Parses a file name (no folders) of the form `<seq>_<frame>.<extension>` with a non-empty seq
/// without '_' and a frame of decimal digits; std::nullopt for anything else.
std::optional<ViperFrameName> parseViperFrameName(const std::string& file_name);

}  // namespace viper::dataset
