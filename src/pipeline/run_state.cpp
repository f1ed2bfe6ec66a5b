// Writing the run's files with provenance.
// SPDX-License-Identifier: MIT
#include "pipeline/run_state.hpp"

#include <cstdint>

#include "terrapolis/version.hpp"

namespace terrapolis::pipeline {

template <class T>
void RunState::write(const std::string& stage, const std::string& name, const Raster<T>& raster,
                     const std::string& description, Style style) {
  // The output folder is where, not what: it stays out of the provenance so runs compare byte for byte.
  nlohmann::ordered_json parameters = scenario.resolved;
  parameters.erase("output");
  WriteOptions options;
  options.cog = scenario.resolved["outputs"]["cog"].get<bool>();
  options.description = description;
  // Provenance without timestamps, so the same scenario gives the same bytes.
  options.metadata = {{"TERRAPOLIS_VERSION", terrapolis::version},
                      {"TERRAPOLIS_STAGE", stage},
                      {"TERRAPOLIS_SEED", std::to_string(scenario.resolved["seed"].get<std::uint64_t>())},
                      {"TERRAPOLIS_INPUT_SHA256", dem_sha256},
                      {"TERRAPOLIS_SCENARIO", parameters.dump()}};
  write_raster((folder / name).string(), raster, options);
  outputs.push_back({name, stage, description, style, true, 0});
}

template void RunState::write(const std::string&, const std::string&, const Raster<float>&, const std::string&, Style);
template void RunState::write(const std::string&, const std::string&, const Raster<std::uint8_t>&, const std::string&, Style);
template void RunState::write(const std::string&, const std::string&, const Raster<std::int32_t>&, const std::string&, Style);
template void RunState::write(const std::string&, const std::string&, const Raster<std::uint32_t>&, const std::string&, Style);

void RunState::write(const std::string& stage, const std::string& name, const VectorLayer& layer,
                     const std::string& description, Style style) {
  write_vector((folder / name).string(), layer);
  outputs.push_back({name, stage, description, style, false, layer.features.size()});
  vectors.emplace_back(style, layer);
}

}  // namespace terrapolis::pipeline
