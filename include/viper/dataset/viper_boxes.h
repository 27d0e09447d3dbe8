// VIPER's box files: one CSV per frame, `<root>/<split>/bb/<seq>/<seq>_<frame:05d>.csv`, one line
// per object: class id, instance id, the 2D box (4 values), the 3D box in the object's model
// coordinates (6 values) and the 4x4 matrix from model to camera coordinates, row by row (16
// values): 28 values. Column order from the VIPER devkit's README (github.com/srrichter/viper);
// the order inside the 2D and 3D boxes, which the README leaves open, is defined here and in
// docs/viper_layout.md.
#pragma once

#include "viper/dataset/viper_camera.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

class FileDigests;

/// One line of a box file.
struct ViperBoxRow {
  int class_id = 0;         ///< VIPER class id, 0..255
  int64_t instance_id = 0;  ///< the object's instance id (as in the inst image), >= 0
  /// Tight box of the object's visible pixels: x_min, y_min, x_max, y_max in pixels, the origin
  /// at the top-left corner of the image, max inclusive (a single pixel at (3, 4) is 3, 4, 3, 4).
  std::array<double, 4> box_2d{{0, 0, 0, 0}};
  /// Axis-aligned box in the object's model coordinates: min x, min y, min z, max x, max y, max z.
  std::array<double, 6> box_3d{{0, 0, 0, 0, 0, 0}};
  /// Model -> camera coordinates (OpenGL camera axes: X right, Y up, looking down -Z; metres),
  /// row by row. May carry the model's scale.
  RowMajor4 model_to_camera = identity4();
};

/// Formats one line (no newline), values with 9 significant digits.
std::string formatViperBoxRow(const ViperBoxRow& row);

/// Writes the rows, one per line, no header (an empty file for no objects), replacing the file
/// (written under a temporary name and renamed); with `digests`, records the file's SHA-256 there.
/// Throws std::runtime_error naming `path` if it cannot be written.
void writeViperBoxesCsv(const std::string& path, const std::vector<ViperBoxRow>& rows,
                        FileDigests* digests = nullptr);

/// The rows of a box file, in file order. Blank lines, lines starting with '#' and a first line
/// that does not start with a number (a header) are skipped. A line with another number of values
/// than 28, a value that is not a finite number, a class id outside 0..255 or an instance id that is
/// not a non-negative integer is left out, and `path:line: what is wrong` is appended to
/// `problems`; the other lines are still read. Throws std::runtime_error naming `path` only if the
/// file cannot be opened.
std::vector<ViperBoxRow> readViperBoxesCsv(const std::string& path, std::vector<std::string>& problems);

}  // namespace viper::dataset
