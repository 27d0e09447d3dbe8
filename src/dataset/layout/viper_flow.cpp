#include "viper/dataset/viper_flow.h"

#include "viper/dataset/float16.h"
#include "viper/dataset/npy.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace viper::dataset {
namespace {

void checkFlow(const std::string& path, const FlowImage& flow) {
  if (flow.width == 0 || flow.height == 0 || flow.uv.size() != 2 * flow.pixels())
    throw std::invalid_argument(path + ": flow of " + std::to_string(flow.width) + "x" +
                                std::to_string(flow.height) + " has " + std::to_string(flow.uv.size()) +
                                " values, expected 2 * width * height > 0");
}

// One entry of a flow file: its bytes and what its npy header says.
struct Component {
  std::string name;
  std::vector<uint8_t> bytes;
  NpyHeader header;
  bool half = false;
};

Component loadComponent(const ZipReader& zip, const std::string& key) {
  Component c;
  const std::string entry = key + ".npy";
  c.name = zip.path() + ":" + entry;
  c.bytes = zip.read(entry);
  c.header = decodeNpyHeader(c.bytes.data(), c.bytes.size(), c.name);
  const std::string& d = c.header.descr;
  c.half = d == "<f2" || d == ">f2";
  if (!c.half && d != "<f4" && d != ">f4")
    throw std::runtime_error(c.name + ": dtype '" + d + "' is not float16 or float32 ('<f2', '<f4')");
  const auto& shape = c.header.shape;
  if (shape.size() != 2)
    throw std::runtime_error(c.name + ": array has " + std::to_string(shape.size()) +
                             " dimensions, expected 2 (height, width)");
  if (shape[0] == 0 || shape[1] == 0 || shape[0] > std::numeric_limits<uint32_t>::max() ||
      shape[1] > std::numeric_limits<uint32_t>::max())
    throw std::runtime_error(c.name + ": shape (" + std::to_string(shape[0]) + ", " + std::to_string(shape[1]) +
                             ") is empty or too large");
  return c;
}

// Writes component `channel` of the interleaved flow from c's elements.
void fillChannel(const Component& c, FlowImage& flow, size_t channel) {
  const size_t rows = flow.height, cols = flow.width, n = rows * cols;
  const uint8_t* p = c.bytes.data() + c.header.data_offset;
  const bool big = c.header.descr[0] == '>';
  float* out = flow.uv.data() + channel;
  for (size_t i = 0; i < n; ++i) {
    // Element i of the file is pixel (r, c) in row-major order, or (i % rows, i / rows) in Fortran order.
    const size_t pixel = c.header.fortran_order ? (i % rows) * cols + i / rows : i;
    float value;
    if (c.half) {
      const uint8_t lo = p[2 * i + (big ? 1 : 0)], hi = p[2 * i + (big ? 0 : 1)];
      value = halfToFloat(static_cast<uint16_t>(lo | (hi << 8)));
    } else {
      uint32_t x = 0;
      for (size_t b = 0; b < 4; ++b) x |= static_cast<uint32_t>(p[4 * i + (big ? 3 - b : b)]) << (8 * b);
      std::memcpy(&value, &x, sizeof value);
    }
    out[2 * pixel] = value;
  }
}

std::string shapeText(const std::vector<uint64_t>& s) {
  return "(" + std::to_string(s[0]) + ", " + std::to_string(s[1]) + ")";
}

}  // namespace

ViperFlowWriteStats writeViperFlow(const std::string& path, const FlowImage& flow, const ZipWriteOptions& zip) {
  checkFlow(path, flow);
  return writeViperFlow(path, flow.uv.data(), flow.width, flow.height, zip);
}

ViperFlowWriteStats writeViperFlow(const std::string& path, const float* uv, uint32_t width, uint32_t height,
                                   const ZipWriteOptions& zip) {
  if (width == 0 || height == 0)
    throw std::invalid_argument(path + ": flow of " + std::to_string(width) + "x" + std::to_string(height) +
                                ": a size is 0");
  const size_t n = static_cast<size_t>(width) * height;
  const std::vector<uint8_t> header = encodeNpyHeader("<f2", false, {height, width});
  ViperFlowWriteStats stats;
  std::vector<ZipEntry> entries(2);
  for (size_t channel = 0; channel < 2; ++channel) {
    ZipEntry& e = entries[channel];
    e.name = channel == 0 ? "u.npy" : "v.npy";
    e.bytes.resize(header.size() + 2 * n);
    std::memcpy(e.bytes.data(), header.data(), header.size());
  }
  // npy's "<f2": little-endian halves, the byte order of every CPU this builds for (static_assert
  // below), so the halves are stored as they are.
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "npy <f2 is little-endian");
  uint16_t* u = reinterpret_cast<uint16_t*>(entries[0].bytes.data() + header.size());
  uint16_t* v = reinterpret_cast<uint16_t*>(entries[1].bytes.data() + header.size());
  stats.overflowed = pairsToHalves(uv, n, u, v);
  writeZip(path, entries, zip);
  return stats;
}

FlowImage readViperFlow(const std::string& path) {
  const ZipReader zip(path);
  const Component u = loadComponent(zip, "u");
  const Component v = loadComponent(zip, "v");
  if (u.header.shape != v.header.shape)
    throw std::runtime_error(path + ": u.npy has shape " + shapeText(u.header.shape) + " but v.npy has " +
                             shapeText(v.header.shape));
  FlowImage flow;
  flow.height = static_cast<uint32_t>(u.header.shape[0]);
  flow.width = static_cast<uint32_t>(u.header.shape[1]);
  flow.uv.resize(2 * flow.pixels());
  fillChannel(u, flow, 0);
  fillChannel(v, flow, 1);
  return flow;
}

}  // namespace viper::dataset
