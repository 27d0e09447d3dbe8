// Shared by the camera and box CSV readers and writers (private to viper_dataset).
#pragma once

#include <charconv>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace viper::dataset {
class FileDigests;
}

namespace viper::dataset::csv {

/// Splits a line at commas, trimming spaces, tabs and a trailing '\r' from each field.
std::vector<std::string> splitLine(const std::string& line);

/// Parses a whole field as a double (locale-independent); false for anything else.
bool parseDouble(const std::string& field, double& value);

/// Parses a whole field as a non-negative integer ("12", also "12.0"); false for anything else.
bool parseCount(const std::string& field, uint64_t& value);

/// Appends `value` with 9 significant digits (shortest form, locale-independent).
void appendNumber(std::string& out, double value);

/// Calls `row(line_number, fields)` for each data line of `path`: blank lines and lines starting
/// with '#' are skipped, and so is a first line whose first field is not a number (a header).
/// Throws std::runtime_error naming `path` if it cannot be opened.
void forEachRow(const std::string& path, const std::function<void(size_t, const std::vector<std::string>&)>& row);

/// Parses fields [first, first + n) of `fields` as finite doubles into `out`; returns "" or what is
/// wrong ("value 5 'x' is not a number").
std::string parseValues(const std::vector<std::string>& fields, size_t first, size_t n, double* out);

/// Writes `text` to `path` through a temporary file and a rename; with `digests`, records its
/// SHA-256 there. Throws std::runtime_error naming `path` if it cannot be written.
void writeTextFile(const std::string& path, const std::string& text, FileDigests* digests = nullptr);

}  // namespace viper::dataset::csv
