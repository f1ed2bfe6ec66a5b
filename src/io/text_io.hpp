// Writing a text output (a report, a JSON document) the way every output is written.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

namespace terrapolis {

/// Writes `text` to `path` through a temporary file renamed over it: no partial file is ever left.
/// Refuses an existing `path` unless `overwrite`, and a folder that does not exist.
void write_text_file(const std::string& path, const std::string& text, bool overwrite);

}  // namespace terrapolis
