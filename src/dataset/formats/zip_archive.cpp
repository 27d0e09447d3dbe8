#include "viper/dataset/zip_archive.h"

#include "deflate_writers.h"

#include <zip.h>

#include <algorithm>
#include <ctime>
#include <limits>
#include <set>
#include <stdexcept>

namespace viper::dataset {
namespace {

std::string codeText(int code) {
  zip_error_t error;
  zip_error_init_with_code(&error, code);
  std::string text = zip_error_strerror(&error);
  zip_error_fini(&error);
  return text;
}

// Entries are small (an image); a size beyond this in a central directory is damage.
constexpr zip_uint64_t kMaxEntrySize = zip_uint64_t(1) << 32;

}  // namespace

void writeZip(const std::string& path, const std::vector<ZipEntry>& entries, const ZipWriteOptions& options) {
  if (entries.empty()) throw std::invalid_argument(path + ": a zip archive needs at least one entry");
  if (options.deflate_level < 0 || options.deflate_level > 9)
    throw std::invalid_argument(path + ": deflate level " + std::to_string(options.deflate_level) +
                                " is outside 0..9");
  std::set<std::string> names;
  for (const auto& e : entries)
    if (e.name.empty() || !names.insert(e.name).second)
      throw std::invalid_argument(path + ": empty or duplicate zip entry name '" + e.name + "'");

  detail::writeFileAtomically(path, detail::zipBytes(entries, options.deflate_level), "zip archive", options.digests);
}

struct ZipReader::Handle {
  zip_t* za = nullptr;
  ~Handle() {
    if (za != nullptr) zip_discard(za);
  }
};

ZipReader::ZipReader(const std::string& path) : path_(path), handle_(std::make_unique<Handle>()) {
  int code = 0;
  handle_->za = zip_open(path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &code);
  if (handle_->za == nullptr) throw std::runtime_error(path + ": cannot open zip archive: " + codeText(code));
}

ZipReader::~ZipReader() = default;

std::vector<std::string> ZipReader::names() const {
  std::vector<std::string> out;
  const zip_int64_t n = zip_get_num_entries(handle_->za, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* name = zip_get_name(handle_->za, static_cast<zip_uint64_t>(i), 0);
    if (name != nullptr) out.emplace_back(name);
  }
  return out;
}

bool ZipReader::has(const std::string& name) const { return zip_name_locate(handle_->za, name.c_str(), 0) >= 0; }

std::vector<uint8_t> ZipReader::read(const std::string& name) const {
  const std::string what = path_ + ": entry '" + name + "'";
  const zip_int64_t index = zip_name_locate(handle_->za, name.c_str(), 0);
  if (index < 0) {
    std::string present;
    for (const auto& n : names()) present += (present.empty() ? "" : ", ") + n;
    throw std::runtime_error(what + " is missing (entries: " + (present.empty() ? "none" : present) + ")");
  }
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(handle_->za, static_cast<zip_uint64_t>(index), 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE))
    throw std::runtime_error(what + ": cannot stat: " + zip_strerror(handle_->za));
  if (st.size > kMaxEntrySize)
    throw std::runtime_error(what + ": announced size " + std::to_string(st.size) + " is absurd");
  zip_file_t* f = zip_fopen_index(handle_->za, static_cast<zip_uint64_t>(index), 0);
  if (f == nullptr) throw std::runtime_error(what + ": cannot open: " + zip_strerror(handle_->za));
  // Grown as data arrives, so that a damaged size field costs no more memory than the data.
  std::vector<uint8_t> bytes;
  bytes.reserve(static_cast<size_t>(std::min<zip_uint64_t>(st.size, zip_uint64_t(1) << 26)));
  std::string error;
  while (bytes.size() < st.size) {
    const size_t have = bytes.size();
    const size_t chunk = static_cast<size_t>(std::min<zip_uint64_t>(st.size - have, zip_uint64_t(1) << 22));
    bytes.resize(have + chunk);
    const zip_int64_t n = zip_fread(f, bytes.data() + have, chunk);
    if (n < 0) {
      error = zip_file_strerror(f);
      break;
    }
    bytes.resize(have + static_cast<size_t>(n));
    if (n == 0) {
      error = "ends after " + std::to_string(have) + " of " + std::to_string(st.size) + " bytes";
      break;
    }
  }
  if (error.empty()) {
    // One more read reaches the end of the entry, where libzip checks the CRC.
    uint8_t extra;
    const zip_int64_t n = zip_fread(f, &extra, 1);
    if (n < 0) error = zip_file_strerror(f);
    else if (n > 0) error = "holds more than its announced " + std::to_string(st.size) + " bytes";
  }
  zip_fclose(f);
  if (!error.empty()) throw std::runtime_error(what + " is damaged: " + error);
  return bytes;
}

}  // namespace viper::dataset
