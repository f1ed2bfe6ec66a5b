// The ridge-altitude linear programs of the planar-maps chapter (§6.3.4.2.2, "méthode du simplexe"),
// solved exactly by CGAL's LP solver. The only source of the planar method that includes CGAL.
// SPDX-License-Identifier: MIT
#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <map>

#include "core/error.hpp"
#include "generate/planar_basins.hpp"

namespace terrapolis::generate {

std::vector<double> solve_min_sum(const std::vector<int>& variables, const std::vector<LinearRow>& rows) {
  std::map<int, int> column;
  for (std::size_t j = 0; j < variables.size(); ++j) column[variables[j]] = int(j);
  // Rows a·z >= c; free variables (no bounds); objective Σ z.
  CGAL::Quadratic_program<double> lp(CGAL::LARGER, false, 0, false, 0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (auto [vertex, coefficient] : rows[i].terms) {
      const auto it = column.find(vertex);
      if (it == column.end()) throw Error(ErrorKind::processing, "planar map: an inequality names a vertex outside its ridge line");
      lp.set_a(it->second, int(i), coefficient);
    }
    lp.set_b(int(i), rows[i].rhs);
  }
  for (std::size_t j = 0; j < variables.size(); ++j) lp.set_c(int(j), 1.0);
  const CGAL::Quadratic_program_solution<CGAL::Gmpzf> solution = CGAL::solve_linear_program(lp, CGAL::Gmpzf());
  if (!solution.is_optimal())
    throw Error(ErrorKind::processing, std::string("planar map: the ridge inequalities have no optimum (") +
                                           (solution.is_infeasible() ? "infeasible" : "unbounded") + ")");
  std::vector<double> z;
  z.reserve(variables.size());
  for (auto v = solution.variable_values_begin(); v != solution.variable_values_end(); ++v) z.push_back(CGAL::to_double(*v));
  return z;
}

}  // namespace terrapolis::generate
