// The writers of the layout's deflated files, PNG and zip (npz): the containers are a few fixed
// headers around one deflate stream each, which libdeflate compresses several times faster than
// zlib at its fastest level and smaller (docs/dataset_generation.md#speed). Reading stays with
// libpng and libzip. Internal to viper_dataset.
#pragma once

#include "viper/dataset/file_digests.h"
#include "viper/dataset/zip_archive.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset::detail {

enum class PngColor : uint8_t { kGray = 0, kRgb = 2, kPalette = 3 };

/// A PNG of 8-bit samples (1 channel for gray and palette, 3 for RGB), every row filtered with
/// PNG's Up filter, the image data deflated by libdeflate at `level` (0..12; 0 stores).
std::vector<uint8_t> pngBytes(const uint8_t* pixels, uint32_t width, uint32_t height, PngColor color,
                              const std::vector<std::array<uint8_t, 3>>& palette, int level);

/// A zip archive of `entries` in order, each deflated at `level` (0: stored), with the fixed entry
/// time 1980-01-01 12:00 so that equal entries give equal bytes. Throws std::invalid_argument for
/// an entry or archive beyond zip's 32-bit sizes (zip64 is not written).
std::vector<uint8_t> zipBytes(const std::vector<ZipEntry>& entries, int level);

/// A path beside `path` for writing before the rename (unique within the process).
std::string temporaryPath(const std::string& path);

/// Writes `bytes` to a temporary file beside `path`, then renames it onto `path`, so that readers
/// never see a half-written file. With `digests`, records the file's SHA-256 there, from `bytes`.
/// Throws std::runtime_error "PATH: cannot write WHAT: reason".
void writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes, const char* what,
                         FileDigests* digests = nullptr);

}  // namespace viper::dataset::detail
