// Numbers in CSV and report tables: the shortest text that reads back to the same double (empty
// for NaN), shared by the evaluation report and the dataset statistics.
#pragma once

#include <charconv>
#include <cmath>
#include <string>

namespace viper {

inline std::string csvNumber(double v) {
  if (std::isnan(v)) return "";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

}  // namespace viper
