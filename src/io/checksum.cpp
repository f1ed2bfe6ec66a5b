// File checksums (SHA-256 through OpenSSL) and library versions.
// SPDX-License-Identifier: MIT
#include "io/checksum.hpp"

#include <GeographicLib/Config.h>
#include <openssl/evp.h>
#include <gdal.h>
#include <proj.h>
#include <tbb/version.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include "core/error.hpp"

namespace terrapolis {

std::string file_sha256(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bad_input(path + ": cannot be read");
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr);
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx, buffer.data(), std::size_t(in.gcount()));
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx, digest, &length);
  EVP_MD_CTX_free(ctx);
  std::string hex;
  char byte[3];
  for (unsigned int i = 0; i < length; ++i) {
    const unsigned char b = digest[i];
    std::snprintf(byte, sizeof(byte), "%02x", b);
    hex += byte;
  }
  return hex;
}

std::map<std::string, std::string> io_library_versions() {
  return {{"GDAL", GDALVersionInfo("RELEASE_NAME")},
          {"PROJ", proj_info().version},
          {"GeographicLib", GEOGRAPHICLIB_VERSION_STRING},
          {"oneTBB", TBB_VERSION_STRING}};
}

}  // namespace terrapolis
