// Small text helpers shared by option and schema parsing.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace terrapolis {

/// The finite number spelled by the whole of `text`, or nullopt ("3x", "", "nan" are not numbers).
inline std::optional<double> parse_number(const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// A JSON pointer ("/density/weights/0") from valijson's error context ("<root>", "[density]", "[\"x\"]").
inline std::string json_pointer_of(const std::vector<std::string>& context) {
  std::string p;
  for (const auto& c : context) {
    if (c == "<root>") continue;
    std::string_view token = c;
    if (token.size() >= 2 && token.front() == '[' && token.back() == ']') token = token.substr(1, token.size() - 2);
    if (token.size() >= 2 && token.front() == '"' && token.back() == '"') token = token.substr(1, token.size() - 2);
    p.push_back('/');
    p.append(token);
  }
  return p.empty() ? "/" : p;
}

}  // namespace terrapolis
