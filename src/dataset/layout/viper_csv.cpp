#include "viper_csv.h"

#include "viper/dataset/file_digests.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace viper::dataset::csv {

std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    std::string f = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const size_t b = f.find_first_not_of(" \t\r");
    const size_t e = f.find_last_not_of(" \t\r");
    fields.push_back(b == std::string::npos ? std::string() : f.substr(b, e - b + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool parseDouble(const std::string& field, double& value) {
  if (field.empty()) return false;
  const char* begin = field.data();
  if (*begin == '+') ++begin;  // from_chars takes no leading '+', which some writers emit
  const char* end = field.data() + field.size();
  const auto r = std::from_chars(begin, end, value);
  return r.ec == std::errc() && r.ptr == end;
}

bool parseCount(const std::string& field, uint64_t& value) {
  double d = 0;
  if (!parseDouble(field, d) || !(d >= 0) || d > 9.0e15 || d != std::floor(d)) return false;
  value = static_cast<uint64_t>(d);
  return true;
}

void appendNumber(std::string& out, double value) {
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 9);
  out.append(buffer, r.ptr);
}

void forEachRow(const std::string& path, const std::function<void(size_t, const std::vector<std::string>&)>& row) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  std::string line;
  size_t number = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const std::vector<std::string> fields = splitLine(line);
    double ignored = 0;
    if (first && !parseDouble(fields[0], ignored)) {
      first = false;
      continue;
    }
    first = false;
    row(number, fields);
  }
}

std::string parseValues(const std::vector<std::string>& fields, size_t first, size_t n, double* out) {
  for (size_t i = 0; i < n; ++i) {
    const std::string& f = fields[first + i];
    if (!parseDouble(f, out[i])) return "value " + std::to_string(first + i + 1) + " '" + f + "' is not a number";
    if (!std::isfinite(out[i])) return "value " + std::to_string(first + i + 1) + " '" + f + "' is not finite";
  }
  return "";
}

void writeTextFile(const std::string& path, const std::string& text, FileDigests* digests) {
  static std::atomic<unsigned> counter{0};
  const std::string tmp = path + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
    out << text;
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write: rename failed: " + std::strerror(e));
  }
  if (digests) digests->record(path, text.size(), sha256Hex(text.data(), text.size()));
}

}  // namespace viper::dataset::csv
