// A single pass over the text: strings skipped, nesting counted, numbers converted, keys tracked
// so that a bad number is named by its JSON pointer.
// SPDX-License-Identifier: MIT
#include "core/json_input.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.hpp"

namespace terrapolis {
namespace {

struct Level {
  bool object = false;
  std::size_t index = 0;  ///< arrays: element number
  std::string key;        ///< objects: the last key read
};

std::string pointer(const std::vector<Level>& levels) {
  std::string p;
  for (const Level& l : levels) p += "/" + (l.object ? l.key : std::to_string(l.index));
  return p.empty() ? "/" : p;
}

}  // namespace

void check_json_text(std::string_view text, const std::string& origin) {
  if (text.size() > kMaxJsonBytes)
    throw bad_input(origin + ": JSON text of " + std::to_string(text.size() >> 20) + " MB is larger than the " +
                    std::to_string(kMaxJsonBytes >> 20) + " MB accepted");
  std::vector<Level> levels;
  bool expect_key = false;  // inside an object, before a ':'
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      const std::size_t start = ++i;
      while (i < text.size() && text[i] != '"') i += text[i] == '\\' ? 2 : 1;
      if (expect_key && !levels.empty()) levels.back().key = std::string(text.substr(start, std::min(i, text.size()) - start));
    } else if (c == '{' || c == '[') {
      if (int(levels.size()) >= kMaxJsonDepth)
        throw bad_input(origin + ": JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels at " + pointer(levels));
      levels.push_back({c == '{', 0, ""});
      expect_key = c == '{';
    } else if (c == '}' || c == ']') {
      if (!levels.empty()) levels.pop_back();
      expect_key = false;
    } else if (c == ':') {
      expect_key = false;
    } else if (c == ',') {
      if (!levels.empty()) {
        ++levels.back().index;
        expect_key = levels.back().object;
      }
    } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
      std::size_t end = i;
      while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || std::string_view("+-.eE").find(text[end]) != std::string_view::npos))
        ++end;
      const std::string number(text.substr(i, end - i));
      errno = 0;
      const double v = std::strtod(number.c_str(), nullptr);
      if (errno == ERANGE && std::isinf(v))
        throw bad_input(origin + ": " + pointer(levels) + ": number " + number + " is out of range");
      i = end - 1;
    }
  }
}

std::string read_json_file(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxJsonBytes)
    throw bad_input(path + ": JSON file of " + std::to_string(size >> 20) + " MB is larger than the " +
                    std::to_string(kMaxJsonBytes >> 20) + " MB accepted");
  std::ifstream in(path, std::ios::binary);
  if (!in || std::filesystem::is_directory(path, ec)) throw bad_input(path + ": no such file");
  std::ostringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  check_json_text(s, path);
  return s;
}

std::string json_error_text(const char* what) {
  std::string_view s = what;
  if (s.starts_with("[json.exception.")) {
    const auto close = s.find("] ");
    if (close != std::string_view::npos) s.remove_prefix(close + 2);
  }
  return std::string(s);
}

}  // namespace terrapolis
