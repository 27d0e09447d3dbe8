#include "deflate_writers.h"

#include <libdeflate.h>

#include <limits>
#include <stdexcept>

namespace viper::dataset::detail {
namespace {

void put16(std::vector<uint8_t>& out, uint32_t v) {
  out.push_back(static_cast<uint8_t>(v));
  out.push_back(static_cast<uint8_t>(v >> 8));
}
void put32(std::vector<uint8_t>& out, uint32_t v) {
  put16(out, v & 0xffff);
  put16(out, v >> 16);
}

constexpr uint32_t kDosTime = 12 << 11;              // 12:00:00
constexpr uint32_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01
constexpr uint64_t kMax32 = std::numeric_limits<uint32_t>::max();

struct Written {
  uint32_t crc = 0, compressed = 0, size = 0, offset = 0;
  uint16_t method = 0;
};

// The fields a local header and a central directory entry share, from "version needed" on.
void commonFields(std::vector<uint8_t>& out, const Written& w, const std::string& name) {
  put16(out, 20);  // version needed: 2.0 (deflate)
  put16(out, 1 << 11);  // names are UTF-8
  put16(out, w.method);
  put16(out, kDosTime);
  put16(out, kDosDate);
  put32(out, w.crc);
  put32(out, w.compressed);
  put32(out, w.size);
  put16(out, static_cast<uint32_t>(name.size()));
  put16(out, 0);  // no extra field
}

}  // namespace

std::vector<uint8_t> zipBytes(const std::vector<ZipEntry>& entries, int level) {
  if (entries.size() > 0xffff) throw std::invalid_argument("more than 65535 zip entries need zip64");
  // This thread's deflate buffer, kept: fresh megabytes a file cost page faults.
  thread_local std::vector<uint8_t> data;
  std::vector<uint8_t> out;
  std::vector<Written> written;
  for (const ZipEntry& e : entries) {
    if (e.bytes.size() > kMax32 || e.name.size() > 0xffff)
      throw std::invalid_argument("zip entry '" + e.name + "' is beyond zip's 32-bit sizes (zip64 is not written)");
    Written w;
    w.crc = libdeflate_crc32(0, e.bytes.data(), e.bytes.size());
    w.size = static_cast<uint32_t>(e.bytes.size());
    w.method = level > 0 ? 8 : 0;
    const uint8_t* payload = e.bytes.data();
    size_t payload_size = e.bytes.size();
    if (level > 0) {
      deflateInto(data, e.bytes.data(), e.bytes.size(), level, DeflateWrapper::kRaw);
      payload_size = data.size();
      payload = data.data();
    }
    if (out.size() > kMax32 || payload_size > kMax32) throw std::invalid_argument("zip archive beyond 4 GiB needs zip64");
    w.compressed = static_cast<uint32_t>(payload_size);
    w.offset = static_cast<uint32_t>(out.size());
    put32(out, 0x04034b50);
    commonFields(out, w, e.name);
    out.insert(out.end(), e.name.begin(), e.name.end());
    out.insert(out.end(), payload, payload + payload_size);
    written.push_back(w);
  }
  if (out.size() > kMax32) throw std::invalid_argument("zip archive beyond 4 GiB needs zip64");
  const uint32_t directory = static_cast<uint32_t>(out.size());
  for (size_t i = 0; i < entries.size(); ++i) {
    put32(out, 0x02014b50);
    put16(out, 20);  // made by: MS-DOS attributes, version 2.0
    commonFields(out, written[i], entries[i].name);
    put16(out, 0);   // no comment
    put16(out, 0);   // disk 0
    put16(out, 0);   // internal attributes
    put32(out, 0);   // external attributes
    put32(out, written[i].offset);
    out.insert(out.end(), entries[i].name.begin(), entries[i].name.end());
  }
  const uint32_t directory_size = static_cast<uint32_t>(out.size() - directory);
  put32(out, 0x06054b50);
  put16(out, 0);
  put16(out, 0);
  put16(out, static_cast<uint32_t>(entries.size()));
  put16(out, static_cast<uint32_t>(entries.size()));
  put32(out, directory_size);
  put32(out, directory);
  put16(out, 0);  // no comment
  return out;
}

}  // namespace viper::dataset::detail
