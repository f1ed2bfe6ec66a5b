// `terrapolis calibrate DEM... --settlements PLACES...`: fits the density model's weights to real
// settlements by a presence/background logistic likelihood (Warton & Shepherd 2010), with held-out skill.
// SPDX-License-Identifier: MIT
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>

#include <nlohmann/json.hpp>

#include "cli/command.hpp"
#include "cli/commands_list.hpp"
#include "cli/dem_input.hpp"
#include "cli/schema_options.hpp"
#include "core/error.hpp"
#include "density/boosted.hpp"
#include "density/calibration.hpp"
#include "hydro/hydro.hpp"
#include "io/output_set.hpp"
#include "io/raster_io.hpp"
#include "io/text_io.hpp"
#include "pipeline/places.hpp"
#include "pipeline/scenario.hpp"
#include "pipeline/stage_options.hpp"
#include "pipeline/stages.hpp"
#include "sites/sites.hpp"

namespace terrapolis::cli {
namespace {

using json = nlohmann::ordered_json;
constexpr std::size_t kTerms = density::kTermCount;

/// One region: its presences and background sample (terms), and every land cell for the AUC.
struct Region {
  std::string name;
  std::vector<density::Terms> presence, background, land;
  std::vector<double> population;
  int dropped = 0;
  density::Skill baselines;  // baselines only (the density field is not used)
  std::vector<double> sizes;  // populations of min_population or more
};

/// A fitted model's scores of cells by their terms: only their order matters (the AUC).
using Scores = std::function<std::vector<double>(const std::vector<density::Terms>&)>;

Scores linear_scores(std::vector<double> beta) {
  return [beta = std::move(beta)](const std::vector<density::Terms>& cells) {
    std::vector<double> out;
    out.reserve(cells.size());
    for (const auto& x : cells) {
      double s = 0;
      for (std::size_t j = 0; j < kTerms; ++j) s += beta[j + 1] * x[j];
      out.push_back(s);
    }
    return out;
  };
}

/// The boosted trees' columns: the fitted terms of each cell, row after row.
std::vector<float> term_rows(const std::vector<density::Terms>& cells, const std::vector<std::size_t>& fitted) {
  std::vector<float> rows;
  rows.reserve(cells.size() * fitted.size());
  for (const auto& x : cells)
    for (std::size_t j : fitted) rows.push_back(float(x[j]));
  return rows;
}

Scores boosted_scores(std::shared_ptr<const density::BoostedModel> model, std::vector<std::size_t> fitted) {
  return [model = std::move(model), fitted = std::move(fitted)](const std::vector<density::Terms>& cells) {
    const std::vector<float> m = model->margins(term_rows(cells, fitted));
    return std::vector<double>(m.begin(), m.end());
  };
}

/// AUCs (plain and population-weighted) of a model's scores on a region, presences restricted to `use` (empty: all).
std::pair<double, double> region_auc(const Scores& scores, const Region& r, const std::vector<std::size_t>& use = {}) {
  const std::vector<double> bg = scores(r.land), all = scores(r.presence);
  std::vector<double> pres, w;
  auto add = [&](std::size_t k) { pres.push_back(all[k]), w.push_back(r.population[k]); };
  if (use.empty())
    for (std::size_t k = 0; k < r.presence.size(); ++k) add(k);
  else
    for (std::size_t k : use) add(k);
  return {density::auc(pres, {}, bg), density::auc(pres, w, bg)};
}

/// The fitting sample: each training region's presences weigh 1 in all, its background 1 in all,
/// so regions count equally whatever their number of places. Presences in `held_out` of region
/// `fold_region` are left out.
struct Sample {
  std::vector<const density::Terms*> x;
  std::vector<double> y, w;
};
Sample training_sample(const std::vector<Region>& regions, const std::vector<bool>& train, int fold_region, const std::vector<std::size_t>& held_out) {
  Sample s;
  for (std::size_t g = 0; g < regions.size(); ++g) {
    if (!train[g]) continue;
    const Region& r = regions[g];
    std::vector<bool> skip(r.presence.size(), false);
    if (int(g) == fold_region)
      for (std::size_t k : held_out) skip[k] = true;
    std::size_t kept = 0;
    for (std::size_t k = 0; k < r.presence.size(); ++k) kept += !skip[k];
    if (kept == 0) continue;
    for (std::size_t k = 0; k < r.presence.size(); ++k)
      if (!skip[k]) s.x.push_back(&r.presence[k]), s.y.push_back(1), s.w.push_back(1.0 / double(kept));
    for (const auto& b : r.background) s.x.push_back(&b), s.y.push_back(0), s.w.push_back(1.0 / double(r.background.size()));
  }
  if (s.x.empty()) throw bad_input("calibrate: no places to fit on");
  return s;
}

/// Gradient-boosted trees (XGBoost) on the fitted terms, on the same sample as the logistic fit.
std::shared_ptr<const density::BoostedModel> fit_boosted(const std::vector<Region>& regions, const std::vector<std::size_t>& fitted,
                                                         const std::vector<bool>& train, const density::BoostedModel::Parameters& parameters,
                                                         int fold_region = -1, const std::vector<std::size_t>& held_out = {}) {
  const Sample s = training_sample(regions, train, fold_region, held_out);
  std::vector<float> rows, labels(s.y.begin(), s.y.end()), weights(s.w.begin(), s.w.end());
  rows.reserve(s.x.size() * fitted.size());
  for (const density::Terms* x : s.x)
    for (std::size_t j : fitted) rows.push_back(float((*x)[j]));
  std::vector<std::string> names;
  for (std::size_t j : fitted) names.push_back(density::term_names()[j]);
  return std::make_shared<const density::BoostedModel>(density::BoostedModel::fit(names, rows, labels, weights, parameters));
}

/// Pooled logistic fit of the terms in `fitted` (the others weigh 0) on the training sample.
/// Returns {b0, b...} over every term.
std::vector<double> fit(const std::vector<Region>& regions, const std::vector<std::size_t>& fitted, const std::vector<bool>& train, double ridge,
                        int fold_region = -1, const std::vector<std::size_t>& held_out = {}) {
  const Sample s = training_sample(regions, train, fold_region, held_out);
  std::vector<std::vector<double>> x;
  x.reserve(s.x.size());
  for (const density::Terms* t : s.x) {
    std::vector<double> v;
    for (std::size_t j : fitted) v.push_back((*t)[j]);
    x.push_back(std::move(v));
  }
  const std::vector<double> b = density::fit_logistic(x, s.y, s.w, ridge);
  std::vector<double> beta(kTerms + 1, 0.0);
  beta[0] = b[0];
  for (std::size_t j = 0; j < fitted.size(); ++j) beta[fitted[j] + 1] = b[j + 1];
  return beta;
}

json auc_pair(std::pair<double, double> a) {
  auto r = [](double v) { return std::isfinite(v) ? json(std::round(v * 1000) / 1000) : json(nullptr); };
  return {{"auc", r(a.first)}, {"weighted_auc", r(a.second)}};
}

class CalibrateCommand final : public Command {
 public:
  std::string name() const override { return "calibrate"; }
  std::string summary() const override {
    return "Fit the density model to real settlements (weights by a presence/background likelihood, or boosted trees) and report its skill";
  }

  void setup(CLI::App& app) override {
    file_kind(app.add_option("DEM", dems_, "DEM(s) of the region(s), any GDAL raster")->required(), FileKind::raster_in);
    dem_.add_read_options(app, "of every DEM");
    file_kind(app.add_option("--settlements", places_, "Real places of each DEM, in the same order: GeoJSON/GPKG points or CSV (lon,lat) with a population field")
        ->required(), FileKind::file_in);
    file_kind(app.add_option("--scenario", scenarios_, "Scenario whose water, hydro and density options are used: one for every DEM, or one per DEM in order (default: the defaults)"), FileKind::file_in);
    file_kind(app.add_option("--fragment", fragment_, "Write the fitted model as a scenario fragment (JSON) to this file (boosted: the trees beside it, F.boosted.json)"),
              FileKind::file_out);
    app.add_option("--model", model_,
                   "logistic: weights of the terms (the density's weighted sum); boosted: gradient-boosted trees over them (XGBoost); "
                   "auto: both, the fragment of the one with the higher mean held-out AUC")
        ->check(CLI::IsMember({"logistic", "boosted", "auto"}))
        ->capture_default_str();
    app.add_option("--trees", boosted_.rounds, "Boosted: number of trees")->check(CLI::Range(1, 5000))->capture_default_str();
    app.add_option("--depth", boosted_.max_depth, "Boosted: largest depth of a tree")->check(CLI::Range(1, 12))->capture_default_str();
    app.add_option("--learning-rate", boosted_.learning_rate, "Boosted: shrinkage of each tree")->check(CLI::Range(0.001, 1.0))->capture_default_str();
    app.add_option("--min-leaf-weight", boosted_.min_child_weight, "Boosted: smallest weight (hessian) of a leaf, the sample's mean weight 1")
        ->check(CLI::Range(0.0, 1e6))
        ->capture_default_str();
    file_kind(app.add_option("--report", report_, "Write the report as JSON to this file"), FileKind::file_out);
    app.add_option("--folds", folds_, "Folds of the cross-validation within a region (one region given)")->check(CLI::Range(2, 100))->capture_default_str();
    app.add_option("--background", background_, "Background cells sampled per region for the fit")->check(CLI::Range(100, 10000000))->capture_default_str();
    app.add_option("--ridge", ridge_, "Ridge penalty on the weights (times the total weight)")->check(CLI::NonNegativeNumber)->capture_default_str();
    app.add_option("--terms", terms_, "Terms to fit, the others weigh 0 (default: every term: " + join(density::term_names()) + ")")->delimiter(',');
    app.add_option("--seed", seed_, "Seed of the background sample and of the folds")->capture_default_str();
    add_overwrite_flag(app, overwrite_);
  }

  void run(Context& context) override {
    if (dems_.size() != places_.size())
      throw bad_input("--settlements: give one places file per DEM (" + std::to_string(dems_.size()) + " DEMs, " + std::to_string(places_.size()) + " files)");
    std::vector<std::string> inputs = dems_;
    inputs.insert(inputs.end(), places_.begin(), places_.end());
    inputs.insert(inputs.end(), scenarios_.begin(), scenarios_.end());
    OutputSet outputs("calibrate", inputs, overwrite_);  // refused before any work
    const std::string fragment_file = fragment_.empty() ? "" : outputs.file(fragment_);
    const std::string report_file = report_.empty() ? "" : outputs.file(report_);
    // Boosted: the trees beside the fragment, which names them relative to itself.
    const std::filesystem::path model_name = std::filesystem::path(fragment_).replace_extension(".boosted.json");
    const std::string model_file = fragment_.empty() || !boosted() ? "" : outputs.file(model_name.string());  // written if chosen
    if (scenarios_.size() > 1 && scenarios_.size() != dems_.size())
      throw bad_input("--scenario: give one scenario, or one per DEM (" + std::to_string(dems_.size()) + " DEMs)");
    fitted_ = fitted_terms();  // refused before any work
    std::vector<Region> regions;
    for (std::size_t g = 0; g < dems_.size(); ++g) {
      const pipeline::Scenario scenario = pipeline::load_scenario(scenarios_.empty() ? "" : scenarios_[scenarios_.size() == 1 ? 0 : g]);
      regions.push_back(load_region(dems_[g], places_[g], scenario, scenario.resolved["sites"]["min_population"].get<double>(), context));
    }

    const std::size_t n = regions.size();
    const std::vector<bool> all(n, true);
    const std::vector<double> beta = fit(regions, fitted_, all, ridge_);
    const std::shared_ptr<const density::BoostedModel> trees = boosted() ? fit_boosted(regions, fitted_, all, boosted_) : nullptr;
    const Scores fitted_scores = trees ? boosted_scores(trees, fitted_) : linear_scores(beta);
    json report;
    report["regions"] = json::array();
    double held_sum = 0, logistic_held_sum = 0;
    std::vector<double> thesis(kTerms + 1, 0.0);
    thesis[1] = 1, thesis[2] = 1, thesis[3] = 1.5;  // belhadj2007: coast 1, hydrometry 1, plateau 1.5
    std::printf("%-40s %6s %7s %7s %7s %7s %7s %7s %7s %6s%s\n", "region", "places", "fit", "held", "w.held", "thesis", "-elev", "-slope",
                "coast", "q", boosted() ? "  logit" : "");
    for (std::size_t g = 0; g < n; ++g) {
      const Region& r = regions[g];
      std::pair<double, double> held{NAN, NAN}, logistic_held{NAN, NAN};
      json held_weights = nullptr;
      if (n > 1) {
        std::vector<bool> others(n, true);
        others[g] = false;
        const std::vector<double> b = fit(regions, fitted_, others, ridge_);
        logistic_held = region_auc(linear_scores(b), r);
        held = boosted() ? region_auc(boosted_scores(fit_boosted(regions, fitted_, others, boosted_), fitted_), r) : logistic_held;
        if (!boosted()) held_weights = scaled_weights(b);
      } else {
        held = cross_validated(regions, false);
        if (boosted()) logistic_held = cross_validated(regions, true);
      }
      held_sum += held.first, logistic_held_sum += logistic_held.first;
      const auto in_region = region_auc(fitted_scores, r);
      const auto thesis_auc = region_auc(linear_scores(thesis), r);
      json baselines = json::object();
      for (std::size_t k = 0; k < 3; ++k)
        baselines[density::kBaselineNames[k]] = auc_pair({r.baselines.baseline_auc[k], r.baselines.baseline_weighted_auc[k]});
      double total = 0;
      for (double p : r.sizes) total += p;
      const double q = sites::rank_size_exponent(r.sizes);
      report["regions"].push_back({{"region", r.name},
                                   {"places", r.presence.size()},
                                   {"places_dropped", r.dropped},
                                   {"fitted_in_sample", auc_pair(in_region)},
                                   {n > 1 ? "held_out_region" : "cross_validated", auc_pair(held)},
                                   {"held_out_weights", held_weights},
                                   {"logistic_held_out", boosted() ? auc_pair(logistic_held) : json(nullptr)},
                                   {"belhadj2007", auc_pair(thesis_auc)},
                                   {"baselines", baselines},
                                   {"settlements", {{"count", r.sizes.size()}, {"total", total}, {"largest", r.sizes.empty() ? 0.0 : r.sizes[0]},
                                                    {"rank_size_exponent", std::isfinite(q) ? json(std::round(q * 1000) / 1000) : json(nullptr)}}}});
      std::printf("%-40s %6zu %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %6.2f", r.name.c_str(), r.presence.size(), in_region.first,
                  held.first, held.second, thesis_auc.first, r.baselines.baseline_auc[0], r.baselines.baseline_auc[1], r.baselines.baseline_auc[2], q);
      if (boosted()) std::printf("  %5.3f", logistic_held.first);
      std::printf("\n");
    }
    const json weights = scaled_weights(beta);
    report["weights"] = weights;
    report["terms"] = json::array();
    for (std::size_t j : fitted_) report["terms"].push_back(density::term_names()[j]);
    const std::string method = boosted() ? "gradient-boosted trees (XGBoost, " + std::to_string(boosted_.rounds) + " trees of depth " +
                                               std::to_string(boosted_.max_depth) + ") on a presence/background sample"
                                         : "logistic presence/background";
    // auto: the trees only where they rank the held-out places better than the weights do.
    const bool trees_chosen = trees && (model_ == "boosted" || held_sum > logistic_held_sum);
    report["model"] = model_;
    if (model_ == "auto") {
      report["chosen"] = trees_chosen ? "boosted" : "logistic";
      std::printf("chosen: %s (mean held-out AUC %.3f for the trees, %.3f for the weights)\n", trees_chosen ? "boosted" : "logistic",
                  held_sum / double(n), logistic_held_sum / double(n));
    }
    report["method"] = n > 1 ? method + ", regions weighted equally; held out: leave one region out"
                             : method + "; held out: " + std::to_string(folds_) + "-fold cross-validation on the places";
    std::printf("weights:");
    for (const auto& [k, v] : weights.items()) std::printf(" %s %.4f", k.c_str(), v.get<double>());
    std::printf("\n(fit: in-sample AUC; held: %s AUC, w.: population-weighted; thesis: the belhadj2007 weights; q: rank-size exponent of the places%s)\n",
                n > 1 ? "leave-one-region-out" : "cross-validated", boosted() ? "; logit: the logistic fit's held-out AUC" : "");
    if (!model_file.empty() && trees_chosen) {
      write_text_file(model_file, trees->save_text(), false);
      write_text_file(fragment_file, json({{"density", {{"model", model_name.filename().string()}}}}).dump(2) + "\n", false);
    } else if (!fragment_file.empty()) {
      write_text_file(fragment_file, json({{"density", {{"weights", weights}}}}).dump(2) + "\n", false);
    }
    if (!report_file.empty()) write_text_file(report_file, report.dump(2) + "\n", false);
    outputs.commit();
  }

 private:
  Region load_region(const std::string& dem_path, const std::string& places_path, const pipeline::Scenario& scenario, double min_population,
                     Context& context) {
    const Dem dem = dem_.read(dem_path);
    // The terms a run's density reads: the same hydrometry, rivers and inland water (the lakes the
    // DEM flattens, water.water_mask, the reservoirs), so that the fitted weights are the run's.
    pipeline::HydroForDensity hydro = pipeline::hydro_for_density(scenario, dem, pipeline::inland_water_settings(scenario),
                                                                  pipeline::hydro_options(scenario), true, true, context.progress, context.log);
    density::DensityOptions options = pipeline::density_options(scenario);
    pipeline::read_density_files(scenario, dem, "", options);
    options.water_mask = std::move(hydro.water);
    options.terrain_terms = true;
    options.rivers = std::move(*hydro.rivers);
    const density::DensityResult model = density::compute_density(dem, hydro.hydrometry, options, context.progress);
    const std::vector<std::uint8_t> land = density::land_cells(model);
    Region r;
    r.name = std::filesystem::path(dem_path).stem().string();
    const std::vector<density::Place> places = pipeline::read_places(places_path, dem, land, r.dropped);
    if (places.empty()) throw bad_input(places_path + ": no place on the land of " + dem_path);
    std::vector<std::size_t> cells;
    for (std::size_t i = 0; i < land.size(); ++i)
      if (land[i]) cells.push_back(i), r.land.push_back(density::terms_at(model, i));
    for (const auto& p : places) {
      r.presence.push_back(density::terms_at(model, dem.index(p.col, p.row)));
      r.population.push_back(p.population);
      if (p.population >= min_population) r.sizes.push_back(p.population);
    }
    std::mt19937_64 generator(seed_);
    const std::size_t b = std::min(background_, cells.size());
    for (std::size_t k = 0; k < b; ++k) std::swap(cells[k], cells[k + std::size_t(generator() % (cells.size() - k))]);
    for (std::size_t k = 0; k < b; ++k) r.background.push_back(density::terms_at(model, cells[k]));
    r.baselines = density::skill(model.density, model, places, land);
    context.log.info(r.name + ": " + std::to_string(places.size()) + " places (" + std::to_string(r.dropped) + " off the land or the grid)");
    return r;
  }

  bool boosted() const { return model_ != "logistic"; }  // boosted or auto: the trees are fitted

  /// One region: k-fold cross-validation over its places (seeded folds), held-out AUCs pooled;
  /// `logistic` whatever --model is (the comparison of the boosted trees).
  std::pair<double, double> cross_validated(const std::vector<Region>& regions, bool logistic) {
    const Region& r = regions[0];
    std::vector<std::size_t> order(r.presence.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::mt19937_64 generator(seed_ + 1);
    for (std::size_t k = order.size(); k > 1; --k) std::swap(order[k - 1], order[std::size_t(generator() % k)]);
    std::vector<double> pres, w, bg;
    for (int f = 0; f < folds_; ++f) {
      std::vector<std::size_t> held;
      for (std::size_t k = std::size_t(f); k < order.size(); k += std::size_t(folds_)) held.push_back(order[k]);
      if (held.empty()) continue;
      const Scores scores = !logistic && boosted() ? boosted_scores(fit_boosted(regions, fitted_, {true}, boosted_, 0, held), fitted_)
                                                   : linear_scores(fit(regions, fitted_, {true}, ridge_, 0, held));
      // Scores of different folds are not on one scale: each fold's AUC, weighted by its size.
      const auto a = region_auc(scores, r, held);
      double wp = 0;
      for (std::size_t k : held) wp += r.population[k];
      pres.push_back(a.first * double(held.size())), w.push_back(double(held.size()));
      bg.push_back(a.second * wp), bg.push_back(wp);
    }
    double s = 0, n = 0, sw = 0, nw = 0;
    for (std::size_t k = 0; k < pres.size(); ++k) s += pres[k], n += w[k], sw += bg[2 * k], nw += bg[2 * k + 1];
    return {s / n, nw > 0 ? sw / nw : NAN};
  }

  /// Indices of the --terms (every term when none is given).
  std::vector<std::size_t> fitted_terms() const {
    const auto names = density::term_names();
    std::vector<std::size_t> fitted;
    for (const std::string& t : terms_) {
      const auto at = std::find(names.begin(), names.end(), t);
      if (at == names.end()) throw bad_input("--terms: unknown term '" + t + "' (terms: " + join(names) + ")");
      if (std::find(fitted.begin(), fitted.end(), std::size_t(at - names.begin())) == fitted.end()) fitted.push_back(std::size_t(at - names.begin()));
    }
    if (terms_.empty())
      for (std::size_t j = 0; j < names.size(); ++j) fitted.push_back(j);
    return fitted;
  }

  static std::string join(const std::array<const char*, kTerms>& names) {
    std::string s;
    for (const char* name : names) s += (s.empty() ? "" : ",") + std::string(name);
    return s;
  }

  /// Weights scaled so the largest is 1 in magnitude: the density ranks cells as the linear predictor does.
  static json scaled_weights(const std::vector<double>& beta) {
    double largest = 0;
    for (std::size_t j = 1; j < beta.size(); ++j) largest = std::max(largest, std::abs(beta[j]));
    json weights = json::object();
    for (std::size_t j = 0; j < kTerms; ++j) weights[density::term_names()[j]] = largest > 0 ? std::round(beta[j + 1] / largest * 1e4) / 1e4 : 0.0;
    return weights;
  }

  std::vector<std::string> dems_, places_, scenarios_, terms_;
  DemInput dem_;  // --band and --assume-crs of the DEMs
  std::vector<std::size_t> fitted_;
  std::string fragment_, report_, model_ = "logistic";
  density::BoostedModel::Parameters boosted_;
  int folds_ = 5;
  std::size_t background_ = 20000;
  double ridge_ = 1e-3;
  std::uint64_t seed_ = 1;
  bool overwrite_ = false;
};

}  // namespace

std::unique_ptr<Command> make_calibrate_command() { return std::make_unique<CalibrateCommand>(); }

}  // namespace terrapolis::cli
