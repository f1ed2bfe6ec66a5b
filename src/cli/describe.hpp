// The machine-readable description of the command line (`terrapolis --describe-json`).
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>

#include <string>

namespace CLI { class App; }

namespace terrapolis::cli {

/// Every command with its options: those the scenario schema declares from their schema field
/// (description, unit, default, range, choices, kind), the commands' own from their CLI11
/// declaration (type, default, validators) and their file kind (cli/schema_options.hpp).
nlohmann::ordered_json describe_cli(CLI::App& app, const std::string& version);

}  // namespace terrapolis::cli
