// File checksums (SHA-256 through OpenSSL) and library versions.
// SPDX-License-Identifier: MIT
#include "io/checksum.hpp"

#include <GeographicLib/Config.h>
#include <openssl/evp.h>
#include <gdal.h>
#include <proj.h>
#include <tbb/version.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.hpp"

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

/// The GeoTIFF tiles of a folder DEM, in name order (as the reader joins them).
std::vector<std::filesystem::path> folder_tiles(const std::string& folder) {
  std::vector<std::filesystem::path> tiles;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (entry.is_regular_file() && (ext == ".tif" || ext == ".tiff")) tiles.push_back(entry.path());
  }
  if (ec) throw bad_input(folder + ": cannot be read (" + ec.message() + ")");
  std::sort(tiles.begin(), tiles.end());
  return tiles;
}

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
  for (const auto& tile : folder_tiles(path)) {
    const std::string name = tile.filename().string();
    sha.add(name.c_str(), name.size() + 1);  // the name and its end: renaming a tile changes the mosaic
    sha.add_file(tile.string());
  }
  return sha.hex();
}

std::uintmax_t input_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) return std::filesystem::file_size(path);
  std::uintmax_t bytes = 0;
  for (const auto& tile : folder_tiles(path)) bytes += std::filesystem::file_size(tile);
  return bytes;
}

std::map<std::string, std::string> io_library_versions() {
  return {{"GDAL", GDALVersionInfo("RELEASE_NAME")},
          {"PROJ", proj_info().version},
          {"GeographicLib", GEOGRAPHICLIB_VERSION_STRING},
          {"oneTBB", TBB_VERSION_STRING}};
}

}  // namespace terrapolis
