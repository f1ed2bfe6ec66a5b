// File checksums (SHA-256 through OpenSSL) and library versions.
// SPDX-License-Identifier: MIT
#include "io/checksum.hpp"

#include <GeographicLib/Config.h>
#include <openssl/evp.h>
#include <gdal.h>
#include <proj.h>
#include <tbb/version.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.hpp"
#include "io/raster_io.hpp"

namespace terrapolis {

namespace {

/// A SHA-256 fed piece by piece.
class Sha256 {
 public:
  Sha256() : ctx_(EVP_MD_CTX_new()) { EVP_DigestInit_ex(ctx_, EVP_sha256(), nullptr); }
  ~Sha256() { EVP_MD_CTX_free(ctx_); }
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void add(const char* data, std::size_t n) { EVP_DigestUpdate(ctx_, data, n); }
  void add_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw bad_input(path + ": cannot be read");
    std::vector<char> buffer(1 << 20);
    while (in) {
      in.read(buffer.data(), std::streamsize(buffer.size()));
      if (in.gcount() > 0) add(buffer.data(), std::size_t(in.gcount()));
    }
  }
  std::string hex() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    EVP_DigestFinal_ex(ctx_, digest, &length);
    std::string out;
    char byte[3];
    for (unsigned int i = 0; i < length; ++i) {
      std::snprintf(byte, sizeof(byte), "%02x", digest[i]);
      out += byte;
    }
    return out;
  }

 private:
  EVP_MD_CTX* ctx_;
};

}  // namespace

std::string file_sha256(const std::string& path) {
  Sha256 sha;
  sha.add_file(path);
  return sha.hex();
}

std::string input_sha256(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) return file_sha256(path);
  Sha256 sha;
  for (const std::string& tile : folder_tiles(path)) {
    const std::string name = std::filesystem::path(tile).filename().string();
    sha.add(name.c_str(), name.size() + 1);  // the name and its end: renaming a tile changes the mosaic
    sha.add_file(tile);
  }
  return sha.hex();
}

std::uintmax_t input_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) return std::filesystem::file_size(path);
  std::uintmax_t bytes = 0;
  for (const std::string& tile : folder_tiles(path)) bytes += std::filesystem::file_size(tile);
  return bytes;
}

std::map<std::string, std::string> io_library_versions() {
  return {{"GDAL", GDALVersionInfo("RELEASE_NAME")},
          {"PROJ", proj_info().version},
          {"GeographicLib", GEOGRAPHICLIB_VERSION_STRING},
          {"oneTBB", TBB_VERSION_STRING}};
}

}  // namespace terrapolis
