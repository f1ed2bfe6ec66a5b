// Small parsers shared by the commands.
// SPDX-License-Identifier: MIT

#include "cli/command.hpp"
#include "core/error.hpp"
#include "core/text.hpp"

namespace terrapolis::cli {

double parse_number_option(const std::string& option, const std::string& text) {
  if (const auto v = parse_number(text)) return *v;
  throw bad_input(option + ": '" + text + "' is not a number");
}

std::array<double, 2> parse_pair(const std::string& option, const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) throw bad_input(option + ": expected X,Y but got '" + text + "'");
  return {parse_number_option(option, text.substr(0, comma)), parse_number_option(option, text.substr(comma + 1))};
}

}  // namespace terrapolis::cli
