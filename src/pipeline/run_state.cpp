// Writing the run's files with provenance.
// SPDX-License-Identifier: MIT
#include "pipeline/run_state.hpp"

#include <cstdint>

#include "terrapolis/version.hpp"

namespace terrapolis::pipeline {

namespace {
constexpr std::pair<Style, const char*> kStyleNames[] = {
    {Style::elevation, "elevation"},   {Style::hillshade, "hillshade"},   {Style::unit_ramp, "unit_ramp"},
    {Style::density, "density"},       {Style::mask, "mask"}, {Style::water, "water"},             {Style::flow_direction, "flow_direction"},
    {Style::accumulation, "accumulation"}, {Style::streams, "streams"},   {Style::cities, "cities"},
    {Style::city_extents, "city_extents"}, {Style::network, "network"},   {Style::roads, "roads"},
    {Style::road_sections, "road_sections"}, {Style::sections, "sections"}, {Style::junctions, "junctions"}, {Style::existing_roads, "existing_roads"},
    {Style::corridors, "corridors"}, {Style::access_minutes, "access_minutes"},
    {Style::access_catchments, "access_catchments"}};
}  // namespace

const char* style_name(Style style) {
  for (const auto& [s, name] : kStyleNames)
    if (s == style) return name;
  return "unit_ramp";
}

Style style_from_name(const std::string& name) {
  for (const auto& [s, n] : kStyleNames)
    if (name == n) return s;
  return Style::unit_ramp;
}

void TiledInput::reserve() { reserved_mb = reserve_reader_memory(tiles.limit_mb()); }

WriteOptions RunState::file_options(const std::string& stage, const std::string& name,
                                    const std::vector<std::pair<std::string, std::string>>& metadata) const {
  // The output folder is where, not what: it stays out of the provenance so runs compare byte for byte.
  nlohmann::ordered_json parameters = scenario.resolved;
  parameters.erase("output");
  // So is the cutting into tiles (input.tile_size, input.memory_limit_mb): the same cells either way.
  parameters["input"].erase("tile_size");
  parameters["input"].erase("memory_limit_mb");
  WriteOptions options;
  options.cog = scenario.resolved["outputs"]["cog"].get<bool>();
  options.description = describe_output(name, terms);
  // Provenance without timestamps, so the same scenario gives the same bytes.
  options.metadata = {{"TERRAPOLIS_VERSION", terrapolis::version},
                      {"TERRAPOLIS_STAGE", stage},
                      {"TERRAPOLIS_SEED", std::to_string(scenario.resolved["seed"].get<std::uint64_t>())},
                      {"TERRAPOLIS_INPUT_SHA256", dem_sha256},
                      {"TERRAPOLIS_SCENARIO", parameters.dump()}};
  options.metadata.insert(options.metadata.end(), metadata.begin(), metadata.end());
  options.overwrite = true;  // the run folder is this run's own (a rerun starts from a copy)
  return options;
}

template <class T>
void RunState::write(const std::string& stage, const std::string& name, const Raster<T>& raster,
                     Style style, const std::vector<std::pair<std::string, std::string>>& metadata) {
  const WriteOptions options = file_options(stage, name, metadata);
  write_raster((folder / name).string(), raster, options);
  outputs.push_back({name, stage, options.description, style, true, 0});
}

template <class T>
void RunState::write_tile(const std::string& stage, const MosaicFiles& mosaic, int t, int across, const Raster<T>& raster,
                          const std::vector<std::pair<std::string, std::string>>& metadata) const {
  write_raster(mosaic.tile(t, across), raster, file_options(stage, mosaic.name + ".tif", metadata));
}

void RunState::write_mosaic(const std::string& stage, const MosaicFiles& mosaic, int tiles, int across, Style style) {
  mosaic.finish(tiles, across);
  outputs.push_back({mosaic.name + ".vrt", stage, describe_output(mosaic.name + ".tif", terms), style, true, 0});
}

template void RunState::write(const std::string&, const std::string&, const Raster<float>&, Style,
                              const std::vector<std::pair<std::string, std::string>>&);
template void RunState::write(const std::string&, const std::string&, const Raster<std::uint8_t>&, Style,
                              const std::vector<std::pair<std::string, std::string>>&);
template void RunState::write(const std::string&, const std::string&, const Raster<std::int32_t>&, Style,
                              const std::vector<std::pair<std::string, std::string>>&);
template void RunState::write(const std::string&, const std::string&, const Raster<std::uint32_t>&, Style,
                              const std::vector<std::pair<std::string, std::string>>&);
template void RunState::write_tile(const std::string&, const MosaicFiles&, int, int, const Raster<float>&,
                                   const std::vector<std::pair<std::string, std::string>>&) const;
template void RunState::write_tile(const std::string&, const MosaicFiles&, int, int, const Raster<std::uint8_t>&,
                                   const std::vector<std::pair<std::string, std::string>>&) const;
template void RunState::write_tile(const std::string&, const MosaicFiles&, int, int, const Raster<std::int32_t>&,
                                   const std::vector<std::pair<std::string, std::string>>&) const;

void RunState::write(const std::string& stage, const std::string& name, const VectorLayer& layer, Style style) {
  const std::string description = describe_output(name, terms);
  write_vector((folder / name).string(), layer, true);
  outputs.push_back({name, stage, description, style, false, layer.features.size()});
  vectors.emplace_back(style, layer);
}

}  // namespace terrapolis::pipeline
