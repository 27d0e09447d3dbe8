#include "viper/dataset/viper_layout.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace viper::dataset {
namespace {

void checkPart(const std::string& what, const std::string& value) {
  if (value.empty() || value.find('/') != std::string::npos)
    throw std::invalid_argument("VIPER path: " + what + " '" + value + "' is empty or holds '/'");
}

}  // namespace

std::string viperFramePath(const std::string& root, const std::string& split, const std::string& modality,
                           const std::string& seq, uint64_t frame, const std::string& extension) {
  checkPart("split", split);
  checkPart("modality", modality);
  checkPart("sequence", seq);
  checkPart("extension", extension);
  if (seq.find('_') != std::string::npos)
    throw std::invalid_argument("VIPER path: sequence '" + seq +
                                "' holds '_', which VIPER's file names <seq>_<frame> reserve");
  char number[24];
  std::snprintf(number, sizeof number, "%05llu", static_cast<unsigned long long>(frame));
  const std::string file = seq + "_" + number + "." + extension;
  return (std::filesystem::path(root) / split / modality / seq / file).string();
}

std::optional<ViperFrameName> parseViperFrameName(const std::string& file_name) {
  const size_t underscore = file_name.find('_');
  const size_t dot = file_name.find('.', underscore == std::string::npos ? 0 : underscore);
  if (underscore == std::string::npos || underscore == 0 || dot == std::string::npos || dot == underscore + 1 ||
      dot + 1 >= file_name.size() || file_name.find('/') != std::string::npos)
    return std::nullopt;
  ViperFrameName out;
  out.seq = file_name.substr(0, underscore);
  const std::string digits = file_name.substr(underscore + 1, dot - underscore - 1);
  if (digits.size() > 19) return std::nullopt;
  for (char c : digits) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    out.frame = out.frame * 10 + static_cast<uint64_t>(c - '0');
  }
  out.extension = file_name.substr(dot + 1);
  return out;
}

}  // namespace viper::dataset
