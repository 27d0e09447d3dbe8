#include "viper/dataset/file_digests.h"

#include <openssl/evp.h>

#include <cstdio>
#include <stdexcept>

namespace viper::dataset {

Sha256::Sha256() : ctx_(EVP_MD_CTX_new(), EVP_MD_CTX_free) {
  if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("OpenSSL cannot start a SHA-256");
}

Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(const void* bytes, size_t size) { EVP_DigestUpdate(ctx_.get(), bytes, size); }

std::string Sha256::hex() {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx_.get(), digest, &length);
  EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr);
  std::string hex(2 * length, '0');
  static const char kDigits[] = "0123456789abcdef";
  for (unsigned int i = 0; i < length; ++i) {
    hex[2 * i] = kDigits[digest[i] >> 4];
    hex[2 * i + 1] = kDigits[digest[i] & 15];
  }
  return hex;
}

std::string sha256Hex(const void* bytes, size_t size) {
  Sha256 hash;
  hash.update(bytes, size);
  return hash.hex();
}

void FileDigests::record(const std::filesystem::path& path, uint64_t size, const std::string& sha256) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto [it, added] = files_.try_emplace(path.lexically_normal().string(), Entry{size, sha256});
  if (!added) it->second.sha256.clear();
}

std::string FileDigests::find(const std::filesystem::path& path, uint64_t size_on_disk) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto it = files_.find(path.lexically_normal().string());
  if (it == files_.end() || it->second.size != size_on_disk) return "";
  return it->second.sha256;
}

size_t FileDigests::size() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  size_t n = 0;
  for (const auto& [path, entry] : files_) n += !entry.sha256.empty();
  return n;
}

}  // namespace viper::dataset
