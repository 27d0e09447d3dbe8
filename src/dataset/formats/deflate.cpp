// One deflate stream, for the PNG and zip writers (deflate_writers.h): level 1 by ISA-L's igzip,
// the other levels by libdeflate.
#include "deflate_writers.h"

#include <isa-l/igzip_lib.h>
#include <libdeflate.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

namespace viper::dataset::detail {

namespace {

// ISA-L's level 1 in one call; false if `out` was too small (the caller falls back).
bool igzipLevel1(std::vector<uint8_t>& out, const uint8_t* in, size_t n, DeflateWrapper wrapper) {
  // This thread's level buffer (its hash tables), kept: a fresh one a file costs page faults.
  thread_local std::vector<uint8_t> level_buf(ISAL_DEF_LVL1_DEFAULT);
  // Stored blocks cost 5 bytes in 65535; the rest is room for block headers and the wrapper.
  out.resize(n + n / 8192 + ISAL_DEF_MAX_HDR_SIZE + 1024);
  isal_zstream z{};  // zeroed: isal_deflate_stateless_init leaves hist_bits (the window) and more as it finds them
  isal_deflate_stateless_init(&z);
  z.level = 1;
  z.level_buf = level_buf.data();
  z.level_buf_size = static_cast<uint32_t>(level_buf.size());
  z.gzip_flag = wrapper == DeflateWrapper::kZlib ? IGZIP_ZLIB : IGZIP_DEFLATE;
  z.next_in = const_cast<uint8_t*>(in);
  z.avail_in = static_cast<uint32_t>(n);
  z.next_out = out.data();
  z.avail_out = static_cast<uint32_t>(out.size());
  z.end_of_stream = 1;
  z.flush = NO_FLUSH;
  const int rc = isal_deflate_stateless(&z);
  if (rc == STATELESS_OVERFLOW) return false;
  if (rc != COMP_OK) throw std::runtime_error("ISA-L could not deflate (error " + std::to_string(rc) + ")");
  out.resize(z.total_out);
  return true;
}

}  // namespace

void deflateInto(std::vector<uint8_t>& out, const uint8_t* in, size_t n, int level, DeflateWrapper wrapper) {
  if (level < 0 || level > 12) throw std::invalid_argument("deflate level must be 0..12, got " + std::to_string(level));
  if (level == 1 && n <= 0xffffffffu - 0x10000u && igzipLevel1(out, in, n, wrapper)) return;
  // This thread's compressors, by level, kept (their tables are megabytes).
  thread_local std::map<int, std::unique_ptr<libdeflate_compressor, decltype(&libdeflate_free_compressor)>> compressors;
  auto& c = compressors.try_emplace(level, nullptr, libdeflate_free_compressor).first->second;
  if (!c) c.reset(libdeflate_alloc_compressor(level));
  if (!c) throw std::runtime_error("libdeflate could not allocate a compressor");
  const bool zlib = wrapper == DeflateWrapper::kZlib;
  out.resize(zlib ? libdeflate_zlib_compress_bound(c.get(), n) : libdeflate_deflate_compress_bound(c.get(), n));
  const size_t size = zlib ? libdeflate_zlib_compress(c.get(), in, n, out.data(), out.size())
                           : libdeflate_deflate_compress(c.get(), in, n, out.data(), out.size());
  if (size == 0) throw std::runtime_error("libdeflate could not deflate");
  out.resize(size);
}

}  // namespace viper::dataset::detail
