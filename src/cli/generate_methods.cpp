// Options of `terrapolis generate --method coast | planar | river`. See generate_methods.hpp.
// SPDX-License-Identifier: MIT
#include "cli/generate_methods.hpp"

#include <cmath>
#include <cstdio>

#include "cli/schema_options.hpp"
#include "core/error.hpp"

namespace terrapolis::cli {

void CoastPlanarOptions::add(CLI::App& app) {
  auto& c = coast;
  file_kind(app.add_option("--coast", coast_path, "coast: polygon(s) of the land, any OGR vector file in any CRS (default: a seeded island)"), FileKind::vector_in);
  app.add_option("--grammar", grammar, "coast: P_c,P_s,P_a of the grammar (Génévaux et al. §4.3), summing to 1")->capture_default_str();
  app.add_option("--edge", c.edge_m, "coast: grammar edge length e (m)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--sigma", c.sigma_m, "coast: least distance σ (m) between two edges, > e/sqrt(2)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--delta", c.delta_m, "coast: least distance δ (m) from an edge to the coast")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--kappa", c.kappa, "coast: greatest slope κ (m/m) between a new node and the nodes near it")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--zeta", c.zeta_m, "coast: altitude window ζ (m) of the mixed selection (0: lowest first; large: priority first)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--lambda", c.lambda, "coast: λ of the ridge heights q_z = max(p_z) + λd (the paper: 0-0.25)")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  app.add_option("--mouth-spacing", c.mouth_spacing_m, "coast: least distance (m) between two river mouths")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--max-priority", c.max_priority, "coast: priority of the most accessible mouth")->capture_default_str()->check(CLI::Range(0, 12));
  app.add_option("--river-grade", c.river_grade, "coast: rise (m/m) of a main-priority river; each lower priority steepens it by sqrt(2)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--primitive-spacing", c.primitive_spacing_m, "coast: spacing (m) of the terrain primitives")
      ->capture_default_str()->check(CLI::PositiveNumber);
  auto& p = planar;
  app.add_option("--tree", p.tree, "planar: the river tree as nested pairs, '.' a source and '(LR)' a confluence, e.g. '((..).)' "
                                   "(default: a random increasing binary tree)");
  app.add_option("--tree-law", tree_law, "planar: law of the random tree: increasing (balanced, §6.4.1 'croissant') or uniform (Rémy)")
      ->capture_default_str()->check(CLI::IsMember({"increasing", "uniform"}));
  app.add_option("--nodes", p.nodes, "planar: confluences of the random tree")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--drop", p.drop_m, "planar: CRIV (m) of DALT = CRIV / Strahler^a, the rise of a river vertex above the next one down")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--drop-exponent", p.drop_exponent, "planar: a of DALT")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--bank-slope", p.bank_slope, "planar: least slope (m/m) of a facet towards its river or away from its ridge")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--fractalisations", p.fractalisations, "planar: global fractalisations, x4 facets each")->capture_default_str()->check(CLI::Range(0, 7));
  app.add_option("--meander", p.meander, "planar: C_PONDERAL, pull of a new river vertex towards a facet centre (0: straight)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  auto& r = river;
  app.add_option("--river-convergence", r.convergence, "river: I of Belhadj eq. 1.3, p = (1 - r/r_max)^I pulls the river vertices to the bed")
      ->capture_default_str()->check(CLI::Range(1.0, 1000.0));
  app.add_option("--river-power", r.power, "river: f of Belhadj eq. 1.2, the negative displacement -X S 2^(r^f - r D H) of the river vertices")
      ->capture_default_str()->check(CLI::Range(0.0, 4.0));
  river_drop = app.add_option("--river-drop", r.bed_drop_m, "river: fall (m) of the bed from the source to the mouth (default: 5 % of --relief)")
                   ->check(CLI::NonNegativeNumber);
}

void CoastPlanarOptions::apply(generate::GenerateRequest& request) const {
  double pc = 0, ps = 0, pa = 0;
  char tail = 0;
  if (std::sscanf(grammar.c_str(), "%lf,%lf,%lf%c", &pc, &ps, &pa, &tail) != 3 || pc < 0 || ps < 0 || pa < 0 ||
      std::abs(pc + ps + pa - 1) > 1e-6)
    throw bad_input("--grammar: expected P_c,P_s,P_a, non-negative and summing to 1 (e.g. 0.2,0.7,0.1), got '" + grammar + "'");
  request.coast = coast;
  request.coast.p_continue = pc;
  request.coast.p_symmetric = ps;
  request.coast.p_asymmetric = pa;
  request.planar = planar;
  request.planar.uniform_tree = tree_law == "uniform";
  request.river = river;
  if (river_drop->count() == 0) request.river.bed_drop_m = river_drop_share * request.relief_m;
}

}  // namespace terrapolis::cli
