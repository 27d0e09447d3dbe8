#include "viper/dataset/middlebury_flo.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace viper::dataset {
namespace {

constexpr size_t kHeaderSize = 12;
constexpr int32_t kMaxSide = 1 << 20;

void putU32(uint8_t* p, uint32_t x) {
  for (int b = 0; b < 4; ++b) p[b] = static_cast<uint8_t>(x >> (8 * b));
}
uint32_t getU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}
void putF32(uint8_t* p, float f) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  putU32(p, x);
}
float getF32(const uint8_t* p) {
  const uint32_t x = getU32(p);
  float f;
  std::memcpy(&f, &x, sizeof f);
  return f;
}

bool unknown(float c) { return !(std::fabs(c) <= kFloUnknownThreshold); }  // true for NaN too

[[noreturn]] void fail(const std::string& path, size_t offset, const std::string& what) {
  throw std::runtime_error(path + ": " + what + " (byte offset " + std::to_string(offset) + ")");
}

}  // namespace

void writeMiddleburyFlo(const std::string& path, const FlowImage& flow) {
  if (flow.width == 0 || flow.height == 0 || flow.width > static_cast<uint32_t>(kMaxSide) ||
      flow.height > static_cast<uint32_t>(kMaxSide) || flow.uv.size() != 2 * flow.pixels())
    throw std::invalid_argument(path + ": flow of " + std::to_string(flow.width) + "x" +
                                std::to_string(flow.height) + " has " + std::to_string(flow.uv.size()) +
                                " values, expected 2 * width * height > 0 (sides up to 2^20)");
  const size_t n = flow.pixels();
  std::vector<uint8_t> bytes(kHeaderSize + 8 * n);
  putF32(bytes.data(), kFloTag);
  putU32(bytes.data() + 4, flow.width);
  putU32(bytes.data() + 8, flow.height);
  for (size_t i = 0; i < n; ++i) {
    float u = flow.uv[2 * i], v = flow.uv[2 * i + 1];
    if (unknown(u) || unknown(v)) u = v = kFloUnknownValue;
    putF32(bytes.data() + kHeaderSize + 8 * i, u);
    putF32(bytes.data() + kHeaderSize + 8 * i + 4, v);
  }
  // Written beside the target and renamed, so a reader never sees half a file.
  const std::string partial = path + ".partial";
  {
    errno = 0;
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      const std::string why = errno != 0 ? std::string(": ") + std::strerror(errno) : std::string();
      std::remove(partial.c_str());
      throw std::runtime_error(path + ": cannot write .flo file" + why);
    }
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::remove(partial.c_str());
    throw std::runtime_error(path + ": cannot write .flo file: " + ec.message());
  }
}

FlowImage readMiddleburyFlo(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open .flo file");
  const std::streamoff end = in.tellg();
  std::vector<uint8_t> bytes(end > 0 ? static_cast<size_t>(end) : 0);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (end < 0 || !in) throw std::runtime_error(path + ": cannot read .flo file");
  if (bytes.size() < kHeaderSize)
    fail(path, bytes.size(), "file of " + std::to_string(bytes.size()) + " bytes is shorter than the 12-byte .flo header");
  if (std::memcmp(bytes.data(), "PIEH", 4) != 0) fail(path, 0, "not a .flo file (tag is not \"PIEH\" = 202021.25)");
  const auto width = static_cast<int32_t>(getU32(bytes.data() + 4));
  const auto height = static_cast<int32_t>(getU32(bytes.data() + 8));
  if (width <= 0 || width > kMaxSide) fail(path, 4, "width " + std::to_string(width) + " is outside 1..2^20");
  if (height <= 0 || height > kMaxSide) fail(path, 8, "height " + std::to_string(height) + " is outside 1..2^20");
  FlowImage flow;
  flow.width = static_cast<uint32_t>(width);
  flow.height = static_cast<uint32_t>(height);
  const size_t n = flow.pixels();
  const size_t present = bytes.size() - kHeaderSize;
  if (present != 8 * n)
    fail(path, kHeaderSize + std::min(present, 8 * n),
         std::string(present < 8 * n ? "truncated" : "trailing bytes") + ": " + std::to_string(width) + "x" +
             std::to_string(height) + " needs " + std::to_string(8 * n) + " bytes of flow, the file has " +
             std::to_string(present));
  flow.uv.resize(2 * n);
  for (size_t i = 0; i < n; ++i) {
    float u = getF32(bytes.data() + kHeaderSize + 8 * i), v = getF32(bytes.data() + kHeaderSize + 8 * i + 4);
    if (unknown(u) || unknown(v)) u = v = std::nanf("");
    flow.uv[2 * i] = u;
    flow.uv[2 * i + 1] = v;
  }
  return flow;
}

}  // namespace viper::dataset
