// SPDX-License-Identifier: MIT
#include "io/text_io.hpp"

#include <fstream>

#include "core/error.hpp"
#include "io/gdal_util.hpp"

namespace terrapolis {

void write_text_file(const std::string& path, const std::string& text, bool overwrite) {
  detail::check_output(path, overwrite);
  const std::string tmp = detail::temporary_name(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) {
      detail::discard_file(tmp);
      throw bad_input(path + ": cannot write output");
    }
  }
  detail::commit_file(tmp, path);
}

}  // namespace terrapolis
