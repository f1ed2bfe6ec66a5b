// Writing a text output (a report, a JSON document) the way every output is written; reading one back.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

namespace terrapolis {

/// Writes `text` to `path` through a temporary file renamed over it: no partial file is ever left.
/// Refuses an existing `path` unless `overwrite`, and a folder that does not exist. A failed write
/// (a full disk: "no space left") throws processing_error naming the file.
void write_text_file(const std::string& path, const std::string& text, bool overwrite);

/// The whole content of a text file. Throws bad_input naming the file when it cannot be read.
std::string read_text_file(const std::string& path);

}  // namespace terrapolis
