#include "deflate_writers.h"

#include <libdeflate.h>

#include <stdexcept>

namespace viper::dataset::detail {
namespace {

void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(v >> shift));
}

// A chunk: length, type, data, CRC-32 of type and data.
void chunk(std::vector<uint8_t>& out, const char type[4], const uint8_t* data, size_t size) {
  put32(out, static_cast<uint32_t>(size));
  const size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  put32(out, libdeflate_crc32(0, out.data() + start, out.size() - start));
}

size_t channelsOf(PngColor color) {
  switch (color) {
    case PngColor::kRgb: return 3;
    case PngColor::kRgba: return 4;
    default: return 1;
  }
}

// A PNG of `pixels`: rows of samples of `depth` bits (8, or 16 big-endian), no padding.
std::vector<uint8_t> pngOfRows(const uint8_t* pixels, uint32_t width, uint32_t height, PngColor color,
                               const std::vector<std::array<uint8_t, 3>>& palette, int level, uint8_t depth) {
  if (level < 0 || level > 12) throw std::invalid_argument("PNG deflate level must be 0..12");
  const size_t row = static_cast<size_t>(width) * channelsOf(color) * (depth / 8);
  // Filtered rows: a filter-type byte (2, Up: each byte minus the one above it) and the row.
  // The filtered rows and the deflated data reuse this thread's buffers: fresh megabytes a frame
  // cost page faults on every image.
  thread_local std::vector<uint8_t> filtered, idat;
  filtered.resize((row + 1) * height);
  for (uint32_t y = 0; y < height; ++y) {
    const uint8_t* r = pixels + y * row;
    uint8_t* f = filtered.data() + y * (row + 1);
    f[0] = 2;
    if (y == 0) {
      std::copy(r, r + row, f + 1);
    } else {
      const uint8_t* up = r - row;
      for (size_t x = 0; x < row; ++x) f[1 + x] = static_cast<uint8_t>(r[x] - up[x]);
    }
  }
  deflateInto(idat, filtered.data(), filtered.size(), level, DeflateWrapper::kZlib);
  const size_t deflated = idat.size();

  std::vector<uint8_t> out{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.reserve(deflated + 1024);
  std::vector<uint8_t> ihdr;
  put32(ihdr, width);
  put32(ihdr, height);
  ihdr.insert(ihdr.end(), {depth, static_cast<uint8_t>(color), 0, 0, 0});  // depth, color, deflate, filtering, no interlace
  chunk(out, "IHDR", ihdr.data(), ihdr.size());
  if (color == PngColor::kPalette) {
    std::vector<uint8_t> plte;
    for (const auto& c : palette) plte.insert(plte.end(), c.begin(), c.end());
    chunk(out, "PLTE", plte.data(), plte.size());
  }
  chunk(out, "IDAT", idat.data(), deflated);
  chunk(out, "IEND", nullptr, 0);
  return out;
}

}  // namespace

std::vector<uint8_t> pngBytes(const uint8_t* pixels, uint32_t width, uint32_t height, PngColor color,
                              const std::vector<std::array<uint8_t, 3>>& palette, int level) {
  return pngOfRows(pixels, width, height, color, palette, level, 8);
}

std::vector<uint8_t> pngBytes16(const uint16_t* samples, uint32_t width, uint32_t height, PngColor color,
                                int level) {
  if (color == PngColor::kPalette) throw std::invalid_argument("a 16-bit PNG cannot have a palette");
  const size_t n = static_cast<size_t>(width) * height * channelsOf(color);
  std::vector<uint8_t> big_endian(2 * n);
  for (size_t i = 0; i < n; ++i) {
    big_endian[2 * i] = static_cast<uint8_t>(samples[i] >> 8);
    big_endian[2 * i + 1] = static_cast<uint8_t>(samples[i]);
  }
  return pngOfRows(big_endian.data(), width, height, color, {}, level, 16);
}

}  // namespace viper::dataset::detail
