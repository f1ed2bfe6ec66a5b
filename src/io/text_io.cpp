// SPDX-License-Identifier: MIT
#include "io/text_io.hpp"

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/gdal_util.hpp"

namespace terrapolis {

namespace detail {

int write_bytes(const std::string& path, const void* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return errno;
  int error = 0;
  if (size && std::fwrite(data, 1, size, f) != size) error = errno;
  if (std::fflush(f) != 0 && !error) error = errno;  // a full disk may show only at the last flush
  if (std::fclose(f) != 0 && !error) error = errno;
  return error ? error : 0;
}

}  // namespace detail

void write_text_file(const std::string& path, const std::string& text, bool overwrite) {
  detail::check_output(path, overwrite);
  const std::string tmp = detail::temporary_name(path);
  if (const int error = detail::write_bytes(tmp, text.data(), text.size())) {
    detail::discard_file(tmp);
    throw detail::write_failure(path, error, "");
  }
  detail::commit_file(tmp, path);
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw bad_input(path + ": cannot read it");
  return text.str();
}

}  // namespace terrapolis
