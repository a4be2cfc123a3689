#pragma once
// Least-squares fits of the steady-rheology asymptotes to rheometer data (docs/fitting.md;
// paper SI "Fitting a_0 and phi_j", "Fitting a_inf and phi_c", "Fitting gamma_dot_DST"):
//   low : (a_0, phi_j)            of E12 to minimum relative viscosities,
//   high: (a_inf, phi_c)          of E13 to plateau (maximum) relative viscosities,
//   dst : (phi_i, alpha_i)_i      of the eta_B series E8 through E14 to measured DST shear rates.
// mu_c and every parameter not listed is taken from the base set and never fitted. Residuals are
// logarithmic, r_k = ln(model_k) - ln(data_k), since viscosities and rates span decades; phi_i
// is fitted through ln(phi_i). Solved with Ceres (bounded trust region, autodiff Jacobians);
// standard errors from Ceres' covariance scaled by s^2 = 2 cost/(n - p).
// Pure functions: no files, no printing.
#include <string>
#include <vector>

#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

enum class FitKind { low, high, dst };

/// "low", "high", "dst".
std::string to_string(FitKind kind);
/// Parses "low"/"high"/"dst"; InputError naming `where` otherwise.
FitKind parse_fit_kind(const std::string& text, const std::string& where);

struct FitOptions {
  /// Number of eta_B terms fitted for kind dst; 0 means "as many as the base set has, or 1".
  int terms = 0;
  /// Names the data source in error messages (e.g. the CSV file).
  std::string where = "data";
  /// Cap on trust-region iterations; reaching it is a NumericalError (non-convergence).
  int max_iterations = 200;
};

/// One fitted parameter, as written to the TOML file and printed.
struct FittedParameter {
  std::string name;        ///< key in the preset file, e.g. "phi_j" or "eta_B[1].alpha"
  double value = 0.0;      ///< fitted value (units of that key)
  double std_error = 0.0;  ///< 1-sigma standard error (same units); NaN if not identifiable
};

struct FitResult {
  FitKind kind = FitKind::low;
  SteadyParams params;                      ///< base set with the fitted values replaced
  std::vector<FittedParameter> parameters;  ///< fitted values with standard errors
  int n = 0;                                ///< number of data points
  int p = 0;                                ///< number of fitted parameters
  double rms = 0.0;                         ///< sqrt(mean r_k^2) of the log residuals [-] (0.02 ~ 2 % scatter)
  double cost = 0.0;                        ///< Ceres cost 0.5 sum r_k^2 at the solution
  double residual_variance = 0.0;           ///< s^2 = 2 cost/(n - p)
  int iterations = 0;                       ///< trust-region iterations of the accepted solve
  bool covariance_ok = false;               ///< false: Jacobian rank-deficient, std errors are NaN
  std::string solver_report;                ///< Ceres' one-line summary
};

/// Checks the data (sizes, n >= p + 1, 0 < phi < 1, values > 0 and finite, kind-specific
/// ranges against the base set) and throws InputError naming `options.where`, the point and the
/// rule. `values` are relative viscosities eta_r for low/high and DST rates [1/s] for dst.
void validate_fit_data(FitKind kind, const std::vector<double>& phi, const std::vector<double>& values,
                       const SteadyParams& base, const FitOptions& options = {});

/// Number of parameters fitted for `kind` with this base set and options.
int fit_parameter_count(FitKind kind, const SteadyParams& base, const FitOptions& options = {});

/// Fit `kind` to (phi, values) starting from an initial guess derived from the data alone.
/// Throws InputError for bad data (see validate_fit_data) and NumericalError when the solver
/// does not converge.
FitResult fit(FitKind kind, const std::vector<double>& phi, const std::vector<double>& values, const SteadyParams& base,
              const FitOptions& options = {});

/// The fitted model at phi (relative viscosity for low/high, DST rate [1/s] for dst), evaluated
/// with the library's closed forms E12/E13/E14; NaN where the asymptote does not exist.
double fit_model_value(FitKind kind, const SteadyParams& params, double phi);

}  // namespace oobleck::rheology
