// `terrapolis network CITIES OUTDIR`: the agglomeration network joining the cities (Belhadj §4.3.2).
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <optional>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/output_set.hpp"
#include "io/vector_io.hpp"
#include "network/layers.hpp"
#include "network/network.hpp"
#include "pipeline/stage_options.hpp"
#include "sites/layers.hpp"

namespace terrapolis::cli {
namespace {

class NetworkCommand final : public Command {
 public:
  std::string name() const override { return "network"; }
  std::string summary() const override { return "Join cities by a simplified union of Delaunay triangulations (Belhadj §4.3.2)"; }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("CITIES", cities_, "City points with radius_m (metres), optional id and parent (e.g. cities.geojson from `sites`)")
                  ->required(),
              FileKind::vector_in);
    file_kind(app.add_option("OUTDIR", out_, "Output folder: network.geojson")->required(), FileKind::folder_out);
    file_kind(app.add_option("--dem", dem_.path,
                             "The DEM the cities were placed on (a run's): their centres are put back on its cell centres and the "
                             "network is built in its CRS, as a run builds it (a GeoJSON keeps 7 decimals of lon/lat)"),
              FileKind::raster_in);
    dem_.add_read_options(app, "--dem");
    schema_.setup(app, name());
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    const network::NetworkOptions options = pipeline::network_options(schema_.scenario());
    OutputSet outputs("network", {cities_, dem_.path}, overwrite_);
    const std::string network_path = (outputs.folder(out_) / "network.geojson").string();
    // Lengths are geodesic whatever the CRS: without a DEM, work in WGS 84 longitude/latitude.
    std::optional<RasterHeader> grid;
    if (!dem_.path.empty()) grid = dem_.header(dem_.path);
    const Crs crs = grid ? grid->georef.crs : wgs84();
    const auto t0 = std::chrono::steady_clock::now();
    const VectorLayer layer = read_vector(cities_, crs);
    std::vector<sites::Site> sites = sites::sites_from_layer(layer, cities_);
    if (grid) sites::snap_to_cells(sites, grid->georef, grid->cols, grid->rows);
    const auto t1 = std::chrono::steady_clock::now();
    const network::SiteGraph graph = network::build_network(sites, crs, options, context.progress);
    const auto t2 = std::chrono::steady_clock::now();
    const VectorLayer lines = network::network_layer(graph, sites, crs);
    write_vector(network_path, lines);
    outputs.commit();
    const auto t3 = std::chrono::steady_clock::now();
    const auto seconds = [](auto a, auto b) { return std::to_string(std::chrono::duration<double>(b - a).count()); };
    context.log.detail("network: read " + seconds(t0, t1) + " s, network " + seconds(t1, t2) + " s, write " + seconds(t2, t3) + " s");

    std::size_t kept = 0, family = 0;
    double length = 0;
    for (const auto& e : graph.edges) {
      kept += e.kept;
      family += e.kind == network::EdgeKind::parent_child;
      if (e.kept) length += e.length_m;
    }
    std::printf("network: %zu cities, %zu candidate edges, %zu kept (%zu parent-child), %.1f km of links, k %.2f\n", sites.size(),
                graph.edges.size(), kept, family, length / 1000.0, options.k);
  }

 private:
  std::string cities_, out_;
  DemInput dem_;
  SchemaOptions schema_;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_network_command() { return std::make_unique<NetworkCommand>(); }

}  // namespace terrapolis::cli
