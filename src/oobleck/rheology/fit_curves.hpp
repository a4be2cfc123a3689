#pragma once
// Joint least-squares fit of the steady model (E1–E14, docs/equations.md, steady rheology) to whole flow curves at
// several volume fractions: a chosen subset of the parameters (default a_0, phi_j, a_inf, phi_c,
// tau_star and every eta_B term) against points (phi, shear rate, shear stress). Each point is
// matched to the model's steady state at the same phi and the same measured stress (residual
// ln gamma_dot_model - ln gamma_dot_data; stress-controlled data may sit on any branch, and the
// state at a given stress is found on every branch) or at the same measured rate (residual
// ln tau_model - ln tau_data, the nearest branch where an S-shaped curve has several).
// Solved with Ceres (Levenberg–Marquardt with bounds, central-difference Jacobians of the
// library's own steady states: no second implementation of the laws). Standard errors and the
// correlation matrix from (J^T J)^-1 s^2, s^2 = 2 cost/(n - p). A parameter the data do not
// determine (a Jacobian column of zeros, a rank-deficient Jacobian, or a 1-sigma range beyond the
// limits) is held at the base set's value and the fit redone without it, one at a time, until the
// rest are determined; CurvesFitOptions::strict makes it an InputError naming it instead. Pure: no
// files, no printing.
#include <string>
#include <vector>

#include "oobleck/rheology/fit.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// Which logarithm the residual measures.
enum class CurvesResidual {
  rate,    ///< ln gamma_dot(model at the measured stress) - ln gamma_dot(data)
  stress,  ///< ln tau(model at the measured rate, nearest branch) - ln tau(data)
};
std::string to_string(CurvesResidual r);
/// "rate" or "stress"; InputError naming `where` otherwise.
CurvesResidual parse_curves_residual(const std::string& text, const std::string& where);

/// A box constraint on one fitted parameter, in its own units.
struct ParameterBounds {
  std::string name;
  double lower = 0.0;
  double upper = 0.0;
};

struct CurvesFitOptions {
  /// Names of the fitted parameters (curves_parameter_names()); empty: curves_default_parameters().
  std::vector<std::string> parameters;
  CurvesResidual residual = CurvesResidual::rate;
  /// Extra bounds, intersected with the model's rules (phi_c < phi_j, phi_j > max data phi, a > 0,
  /// 0 <= Delta <= 1, 0 <= alpha <= 60, phi_i > 0).
  std::vector<ParameterBounds> bounds;
  std::string where = "data";  ///< names the data source in messages
  int max_iterations = 1000;
  /// false: a parameter the data do not determine is held at the base set's value (see
  /// CurvesFitResult::held); true: it is an InputError naming it.
  bool strict = false;
};

/// A parameter of the requested set that the fit held at the base set's value, and why.
struct HeldParameter {
  std::string name;
  double value = 0.0;  ///< the base set's value it was held at (its own units)
  /// The rule that held it: "the residuals do not change with it" (a Jacobian column of zeros);
  /// "the Jacobian is rank-deficient: a combination of ... leaves every residual unchanged;
  /// condition ..." (held: the largest component of the null vector); "1 sigma: a factor ...,
  /// beyond a factor 1000" or "1 sigma: +- ..., beyond +- LIMIT" (held: the loosest).
  std::string reason;
};

struct CurvesFitResult {
  Preset fitted;                            ///< base set with the fitted values replaced
  std::vector<FittedParameter> parameters;  ///< fitted values with 1-sigma standard errors
  std::vector<double> covariance;           ///< p x p, row-major, in the parameters' units (scaled by s^2)
  std::vector<double> correlation;          ///< p x p, row-major
  std::vector<double> residuals;            ///< per point: ln(model) - ln(data) of the residual's quantity
  std::vector<double> model;                ///< per point: the model's rate [1/s] or stress [Pa] there
  int n = 0, p = 0;
  double rms = 0.0;    ///< sqrt(mean residual^2)
  double cost = 0.0;   ///< 0.5 sum residual^2
  int iterations = 0;  ///< of the last fit (the one without the held parameters)
  /// Requested parameters held at the base set's values, in the order they were held (empty when
  /// strict, or when the data determine every one); `parameters` holds the rest.
  std::vector<HeldParameter> held;
};

/// Every parameter name the curves fit accepts for this base set: a_0, phi_j, a_inf, phi_c,
/// tau_star, Delta, eta_B[i].phi_i, eta_B[i].alpha (one pair per term of the base set).
std::vector<std::string> curves_parameter_names(const Preset& base);
/// The default subset: a_0, phi_j, a_inf, phi_c, tau_star and every eta_B term of the base set.
std::vector<std::string> curves_default_parameters(const Preset& base);

/// Checks sizes, finiteness, 0 < phi < 1, positive rates and stresses and n > p; InputError
/// naming options.where, the row and the rule.
void validate_curves_data(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                          const std::vector<double>& shear_stress, const Preset& base, const CurvesFitOptions& options);

/// The fit, starting from the base set's values (they must be feasible: phi_j above every data
/// phi). Undetermined parameters are held one at a time (every column of zeros at once; for a
/// rank-deficient Jacobian the parameter with the largest component of the null singular vector;
/// for 1-sigma ranges beyond the limits the one furthest beyond), refitting after each.
/// InputError for bad data, unknown names, infeasible bounds, and undetermined parameters when
/// options.strict or when every parameter would be held; NumericalError when Ceres does not converge.
CurvesFitResult fit_curves(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                           const std::vector<double>& shear_stress, const Preset& base,
                           const CurvesFitOptions& options = {});

}  // namespace oobleck::rheology
