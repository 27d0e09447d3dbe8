// The writers of the layout's deflated files, PNG and zip (npz): the containers are a few fixed
// headers around one deflate stream each. Level 1 (the default) is ISA-L's igzip level 1: a 1080p
// flow npz 2.5 times as fast as libdeflate's level 2, for 1.3 times the bytes (bench_flow_files).
// Levels 2..12 are libdeflate's, several times faster than zlib at each level and smaller
// (docs/dataset_generation.md#speed). Reading stays with libpng and libzip. Internal to
// viper_dataset.
#pragma once

#include "viper/dataset/file_digests.h"
#include "viper/dataset/zip_archive.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset::detail {

enum class DeflateWrapper { kRaw, kZlib };

/// `n` bytes of `in` as one deflate stream (raw, or in zlib's wrapper as PNG wants) into `out`
/// (resized to fit): level 0 stores, 1 is ISA-L's level 1, 2..12 libdeflate's levels. Throws
/// std::invalid_argument for another level.
void deflateInto(std::vector<uint8_t>& out, const uint8_t* in, size_t n, int level, DeflateWrapper wrapper);

enum class PngColor : uint8_t { kGray = 0, kRgb = 2, kPalette = 3, kRgba = 6 };

/// A PNG of 8-bit samples (1 channel for gray and palette, 3 for RGB, 4 for RGBA), every row
/// filtered with PNG's Up filter, the image data deflated at `level` (deflateInto).
std::vector<uint8_t> pngBytes(const uint8_t* pixels, uint32_t width, uint32_t height, PngColor color,
                              const std::vector<std::array<uint8_t, 3>>& palette, int level);

/// A PNG of 16-bit samples (gray, RGB or RGBA; `samples` in host order, channels interleaved),
/// written big-endian as PNG stores them, otherwise as pngBytes. Throws std::invalid_argument
/// for kPalette.
std::vector<uint8_t> pngBytes16(const uint16_t* samples, uint32_t width, uint32_t height, PngColor color,
                                int level);

/// A zip archive of `entries` in order, each deflated at `level` (deflateInto; 0: stored entries), with the fixed entry
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
