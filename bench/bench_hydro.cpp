// In-process timings of the hydrology kernels (Belhadj diffusion; fill, D8 and accumulation).
// SPDX-License-Identifier: MIT
// Usage: bench_hydro [--benchmark_filter=...]; the DEMs come from ../shared/dems next to the repository
// (TERRAPOLIS_BENCH_DEM overrides N47E009.hgt). Threads: TERRAPOLIS_BENCH_THREADS (default 2).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "core/geodesy.hpp"
#include "hydro/accumulation.hpp"
#include "hydro/belhadj_hydrometry.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "io/raster_io.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;

namespace {

std::string dem_path() {
  const char* env = std::getenv("TERRAPOLIS_BENCH_DEM");
  return env ? env : std::string(TERRAPOLIS_SOURCE_DIR) + "/../shared/dems/N47E009.hgt";
}

const Dem& full_dem() {
  static const Dem dem = [] {
    init_gdal();
    return read_dem(dem_path());
  }();
  return dem;
}

/// The thesis's Corsica-sized case: the north-west 256 x 256 corner of the DEM.
Dem corner(int size) {
  const Dem& d = full_dem();
  Georef g = d.georef();
  Dem out(size, size, g);
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) out(c, r) = d(c, r);
  return out;
}

int bench_threads() {
  const char* env = std::getenv("TERRAPOLIS_BENCH_THREADS");
  return env ? std::atoi(env) : 2;
}

/// 20 Belhadj iterations on `dem`, with the cell-iterations rate.
void belhadj_x20(benchmark::State& state, const Dem& dem) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(bench_threads()));
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  BelhadjOptions o;
  o.max_iterations = 20;
  for (auto _ : state) {
    BelhadjRun run = belhadj_hydrometry(dem, m, o, p);
    benchmark::DoNotOptimize(run.hydrometry.values().data());
  }
  state.counters["cell_it_per_s"] =
      benchmark::Counter(double(dem.size()) * 20, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Belhadj256x20(benchmark::State& state) { belhadj_x20(state, corner(256)); }
BENCHMARK(BM_Belhadj256x20)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BelhadjStep256(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(bench_threads()));
  const Dem dem = corner(256);
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  BelhadjModel model(dem, m, VerticalScale::metres, std::nullopt);
  for (int i = 0; i < 5; ++i) model.step();
  for (auto _ : state) benchmark::DoNotOptimize(model.step());
}
BENCHMARK(BM_BelhadjStep256)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_BelhadjFullx20(benchmark::State& state) { belhadj_x20(state, full_dem()); }
BENCHMARK(BM_BelhadjFullx20)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FillD8Accumulation(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(bench_threads()));
  const Dem& dem = full_dem();
  const CellMetrics m = cell_metrics(dem.georef(), dem.cols(), dem.rows());
  SilentProgress p;
  for (auto _ : state) {
    const Dem filled = fill_depressions(dem, {FillMethod::priority_flood, std::nullopt}, p);
    const auto d8 = d8_directions(filled, m, std::nullopt, p);
    const FlowRouter router(filled, d8, m, FlowMethod::d8);
    Raster<double> area = accumulate(filled, router, m, {}, p);
    benchmark::DoNotOptimize(area.values().data());
  }
}
BENCHMARK(BM_FillD8Accumulation)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
