// VIPER's optical-flow files: one .npz (a zip archive, as numpy.savez / savez_compressed write
// it) per frame holding two float16 arrays of shape (height, width): `u.npy` (pixels, right) and
// `v.npy` (pixels, down). A non-finite value marks invalid flow. Details: docs/dataset_io.md.
#pragma once

#include "viper/dataset/flow_image.h"
#include "viper/dataset/zip_archive.h"

#include <cstddef>
#include <string>

namespace viper::dataset {

/// What writeViperFlow did to the values.
struct ViperFlowWriteStats {
  /// Finite components whose magnitude was at least 65520 px and so became +-inf (invalid) in
  /// float16. All other values are rounded to the nearest float16 (relative error <= 2^-11,
  /// i.e. at most 1/32 px below 64 px and 1/2 px below 1024 px).
  size_t overflowed = 0;
};

/// Writes `flow` to `path` as VIPER's .npz: entries "u.npy" and "v.npy", version 1.0 headers,
/// descr '<f2', C order, shape (height, width). Values are converted with floatToHalf: NaN stays
/// NaN, +-inf stays +-inf. `zip.deflate_level` 0 gives numpy.savez's stored entries, 1..9
/// savez_compressed's deflated ones. Throws std::invalid_argument if uv.size() is not
/// 2 * width * height or a size is 0, std::runtime_error naming `path` if it cannot be written.
ViperFlowWriteStats writeViperFlow(const std::string& path, const FlowImage& flow,
                                   const ZipWriteOptions& zip = ZipWriteOptions());
/// The same from interleaved (u, v) values held elsewhere (a flow message's data, no copy):
/// 2 * width * height floats at `uv`. Throws std::invalid_argument if a size is 0.
ViperFlowWriteStats writeViperFlow(const std::string& path, const float* uv, uint32_t width, uint32_t height,
                                   const ZipWriteOptions& zip = ZipWriteOptions());

/// Reads a VIPER flow .npz: entries "u.npy" and "v.npy" (other entries are ignored), stored or
/// deflated, each a 2-D array of float16 or float32 ('<f2', '>f2', '<f4', '>f4') in C or Fortran
/// order; both must have the same shape (height, width). float16 values are widened exactly;
/// non-finite values are returned as they are (NaN, +-inf). Throws std::runtime_error naming
/// `path` (and the entry) if the file is missing or not a readable zip, an entry is missing,
/// corrupt or truncated, the dtype or number of dimensions is wrong, or u and v differ in shape.
FlowImage readViperFlow(const std::string& path);

}  // namespace viper::dataset
