#pragma once
// What the parameter fits (fit.cpp: low, high, dst; fit_curves.cpp: curves) share of Ceres: the
// solver's settings and the convergence check. Included by those two files only.

#include <cmath>
#include <string_view>

#include <ceres/ceres.h>
#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::rheology::detail {

/// Levenberg–Marquardt with dense QR (a handful of parameters), silent, on one thread.
inline ceres::Solver::Options levenberg_marquardt(int max_iterations, double function_tolerance,
                                                  double parameter_tolerance) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = function_tolerance;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = parameter_tolerance;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.num_threads = 1;
  return o;
}

/// Throws NumericalError unless Ceres reports convergence to a finite cost: "WHERE: the KIND fit
/// did not converge after N iterations (TERMINATION: MESSAGE); HINT". N counts the trust-region steps
/// (Summary::iterations also holds the evaluation at the start).
inline void require_convergence(const ceres::Solver::Summary& s, std::string_view where, std::string_view kind,
                                std::string_view hint) {
  if (s.termination_type == ceres::CONVERGENCE && std::isfinite(s.final_cost)) return;
  throw NumericalError(fmt::format("{}: the {} fit did not converge after {} iterations ({}: {}); {}", where, kind,
                                   s.iterations.empty() ? 0 : s.iterations.size() - 1,
                                   ceres::TerminationTypeToString(s.termination_type), s.message, hint));
}

}  // namespace oobleck::rheology::detail
