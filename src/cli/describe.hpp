// The machine-readable description of the command line (`terrapolis --describe-json`).
// SPDX-License-Identifier: MIT
#pragma once
#include <nlohmann/json.hpp>

#include <string>

namespace CLI { class App; }

namespace terrapolis::cli {

/// Every command with its options as CLI11 declared them: name, help, type, default (the bound
/// variable's current value), required, positional, repeatable, choices and ranges from the
/// validators, and the kind of file a path option reads or writes (raster_in, vector_out, ...).
nlohmann::ordered_json describe_cli(CLI::App& app, const std::string& version);

}  // namespace terrapolis::cli
