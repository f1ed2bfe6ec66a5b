// Small parsers shared by the commands.
// SPDX-License-Identifier: MIT

#include "cli/command.hpp"
#include "core/error.hpp"

namespace terrapolis::cli {

std::array<double, 2> parse_pair(const std::string& option, const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) throw bad_input(option + ": expected X,Y but got '" + text + "'");
  std::array<double, 2> v{};
  const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
  for (int i = 0; i < 2; ++i) {
    std::size_t used = 0;
    try {
      v[i] = std::stod(parts[i], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != parts[i].size()) throw bad_input(option + ": '" + parts[i] + "' is not a number");
  }
  return v;
}

}  // namespace terrapolis::cli
