// Bounds on JSON inputs, checked on the raw text before any JSON library parses it.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace terrapolis {

/// Largest JSON input read (scenarios, cost models, parameter files, run.json): 16 MB.
inline constexpr std::size_t kMaxJsonBytes = std::size_t(16) << 20;
/// Deepest nesting of arrays and objects accepted: the scenario schema needs 5 levels, plugin
/// parameters a few more. Parsers, validators and serializers recurse once per level.
inline constexpr int kMaxJsonDepth = 64;

/// Refuses (bad_input, one line naming `origin`) JSON text that is larger than kMaxJsonBytes,
/// nests deeper than kMaxJsonDepth, or holds a number outside the range of a double (1e400),
/// naming the field as a JSON pointer. Other syntax errors are left to the parser.
void check_json_text(std::string_view text, const std::string& origin);

/// The text of a JSON file, refused before reading when larger than kMaxJsonBytes, then checked
/// with check_json_text. Throws bad_input "<path>: no such file" when it cannot be opened.
std::string read_json_file(const std::string& path);

/// A parser's exception text without nlohmann's "[json.exception.parse_error.101] " prefix.
std::string json_error_text(const char* what);

}  // namespace terrapolis
