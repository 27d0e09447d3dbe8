// VIPER's camera files: one CSV per sequence, `<root>/<split>/camera/<seq>.csv`, one line per
// frame: the frame id, then the 4x4 projection matrix and the 4x4 view matrix, each row by row
// (33 values). OpenGL conventions: the view matrix maps world points to camera coordinates with X
// right, Y up and the camera looking down -Z; the projection is OpenGL's (clip coordinates). In
// the release, poses are relative to the first frame (its view matrix is the identity). Column
// order from the VIPER devkit's README (github.com/srrichter/viper); docs/viper_layout.md.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace viper::dataset {

/// A 4x4 matrix, row by row: m[4 * row + column].
using RowMajor4 = std::array<double, 16>;

/// The identity matrix.
RowMajor4 identity4();

/// One line of a camera file.
struct ViperCameraRow {
  uint64_t frame = 0;
  RowMajor4 projection = identity4();  ///< OpenGL projection, row by row
  RowMajor4 view = identity4();        ///< world -> OpenGL camera, row by row
};

/// Path of a sequence's camera file: `<root>/<split>/camera/<seq>.csv`. Throws
/// std::invalid_argument like viperFramePath for empty parts, '/' or a seq with '_'.
std::string viperCameraPath(const std::string& root, const std::string& split, const std::string& seq);

/// Formats one line (no newline): `frame,p00,...,p33,v00,...,v33`, values with 9 significant
/// digits (exact for float32 matrices).
std::string formatViperCameraRow(const ViperCameraRow& row);

/// Writes the rows in the order given, one per line, no header, replacing the file (written under
/// a temporary name and renamed). Throws std::runtime_error naming `path` if it cannot be written.
void writeViperCameraCsv(const std::string& path, const std::vector<ViperCameraRow>& rows);

/// The rows of a camera file, by frame id. Blank lines and lines starting with '#' are skipped; a
/// first line that does not start with a number is taken for a header and skipped. A line with
/// another number of values than 33, a value that is not a number or not finite, a frame id that
/// is not a non-negative integer, or a frame id seen before is left out, and a message
/// `path:line: what is wrong` is appended to `problems`; the other lines are still read. Throws
/// std::runtime_error naming `path` only if the file cannot be opened.
std::map<uint64_t, ViperCameraRow> readViperCameraCsv(const std::string& path, std::vector<std::string>& problems);

}  // namespace viper::dataset
