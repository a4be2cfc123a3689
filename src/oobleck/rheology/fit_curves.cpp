#include "oobleck/rheology/fit_curves.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/least_squares.hpp"
#include "oobleck/rheology/parameter_table.hpp"
#include "oobleck/rheology/steady_states.hpp"

namespace oobleck::rheology {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kStrict = 1e-7;     ///< strict inequalities as inclusive bounds shifted by this
constexpr double kAlphaMax = 60.0;   ///< as the dst fit
constexpr double kCondition = 1e-9;  ///< smallest singular value / largest (scaled J): below, undetermined

/// One fitted parameter: a steady parameter of the table or an E8 term's phi_i or alpha, and
/// whether it is fitted through its logarithm (the positive scales a_0, a_inf, tau_star, phi_i, so
/// that steps are relative).
struct Param {
  enum Kind { scalar, phi_i, alpha } kind = scalar;
  double SteadyParams::*member = nullptr;  ///< kind == scalar: the member its table row names
  int term = 0;                            ///< eta_B term for phi_i, alpha
  std::string name;
  bool log = false;
  double lower = -kInf, upper = kInf;  ///< natural units

  bool is(double SteadyParams::*m) const { return kind == scalar && member == m; }
};

/// The field of `s` that `q` fits (const where `s` is).
template <class S>
auto& slot(S& s, const Param& q) {
  switch (q.kind) {
    case Param::scalar: return s.*q.member;
    case Param::phi_i: return s.eta_B_terms[static_cast<std::size_t>(q.term)].phi_i;
    case Param::alpha: return s.eta_B_terms[static_cast<std::size_t>(q.term)].alpha;
  }
  return s.*q.member;  // unreachable
}

/// The table's steady rows the curves fit takes (parameter_table.hpp, CurvesFit).
std::vector<const Parameter*> fittable_rows(bool by_default_only) {
  std::vector<const Parameter*> rows;
  for (const Parameter& row : parameter_table()) {
    if (row.curves_fit == CurvesFit::by_default || (row.curves_fit == CurvesFit::when_named && !by_default_only))
      rows.push_back(&row);
  }
  return rows;
}

Param parse_param(const std::string& name, const Preset& base, const std::string& where) {
  Param q{};
  q.name = name;
  const auto rows = fittable_rows(false);
  if (auto it = std::find_if(rows.begin(), rows.end(), [&](const Parameter* r) { return r->name == name; });
      it != rows.end()) {
    q.member = (*it)->steady;
    q.log = positive_scale(**it);
  } else {
    int term = -1;
    char field[16] = {0};
    char tail = 0;
    if (std::sscanf(name.c_str(), "eta_B[%d].%15[a-z_]%c", &term, field, &tail) == 2 &&
        (std::string(field) == "phi_i" || std::string(field) == "alpha")) {
      if (term < 0 || term >= static_cast<int>(base.steady.eta_B_terms.size())) {
        throw InputError(fmt::format("{}: parameter '{}': the base set has {} eta_B term(s) (eta_B[0] .. eta_B[{}])",
                                     where, name, base.steady.eta_B_terms.size(),
                                     static_cast<int>(base.steady.eta_B_terms.size()) - 1));
      }
      q.kind = std::string(field) == "phi_i" ? Param::phi_i : Param::alpha;
      q.term = term;
      q.log = q.kind == Param::phi_i;
    } else {
      const auto names = curves_parameter_names(base);
      const std::string hint = closest_match(name, names);
      throw InputError(fmt::format("{}: unknown parameter '{}'{}; the curves fit accepts: {}", where, name,
                                   hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint),
                                   fmt::join(names, ", ")));
    }
  }
  return q;
}

/// Points grouped by phi: each curve is sampled once per evaluation.
struct Group {
  double phi;
  std::vector<int> rows;
};

struct CurvesCost {
  const std::vector<Param>* params;
  SteadyParams base;
  const std::vector<Group>* groups;
  const std::vector<double>* ln_rate;
  const std::vector<double>* ln_stress;
  CurvesResidual residual;
  double max_phi;

  /// The model's parameters at internal values x; false where they break a rule.
  bool apply(const double* x, SteadyParams& s) const {
    s = base;
    for (std::size_t i = 0; i < params->size(); ++i) {
      const Param& q = (*params)[i];
      slot(s, q) = q.log ? std::exp(x[i]) : x[i];
    }
    return s.phi_c > 0.0 && s.phi_c < s.phi_j && s.phi_j < 1.0 && max_phi < s.phi_j && s.a_0 > 0.0 && s.a_inf > 0.0 &&
           s.tau_star > 0.0 && std::isfinite(s.tau_star) && s.Delta >= 0.0 && s.Delta <= 1.0;
  }

  /// Residual and model value of every row; false (with `failed` the row) where a point has no
  /// steady state at its measured stress or rate.
  bool evaluate(const double* x, double* r, double* model, int* failed) const {
    SteadyParams s;
    if (!apply(x, s)) return false;
    try {
      for (const Group& g : *groups) {
        const SteadyCurve curve(s, g.phi);
        for (int k : g.rows) {
          const auto ku = static_cast<std::size_t>(k);
          const bool by_stress = residual == CurvesResidual::rate;  // the measured stress is given
          const auto states = curve.states_at(by_stress ? Control::shear_stress : Control::shear_rate,
                                              std::exp(by_stress ? (*ln_stress)[ku] : (*ln_rate)[ku]));
          double best = kInf, best_model = 0.0;
          for (const SteadyPoint& p : states) {
            const double m = by_stress ? p.shear_rate : p.shear_stress;
            const double res = std::log(m) - (by_stress ? (*ln_rate)[ku] : (*ln_stress)[ku]);
            if (std::fabs(res) < std::fabs(best)) {
              best = res;
              best_model = m;
            }
          }
          if (!std::isfinite(best) && !by_stress) {
            // No state is that fast (above gamma_DST or the S's turning point): the distance from the
            // fastest state, ln tau there plus the excess rate, continues the residual as the
            // matching state runs off to infinite stress (Ceres needs every Jacobian to evaluate).
            const SteadyPoint f = curve.fastest_sample();
            best = std::log(f.shear_stress) - (*ln_stress)[ku] + ((*ln_rate)[ku] - std::log(f.shear_rate));
            best_model = f.shear_stress;
          }
          if (!std::isfinite(best)) {
            if (failed != nullptr) *failed = k;
            return false;
          }
          r[k] = best;
          if (model != nullptr) model[k] = best_model;
        }
      }
    } catch (const NumericalError&) {
      return false;
    }
    return true;
  }

  bool operator()(double const* const* x, double* r) const { return evaluate(x[0], r, nullptr, nullptr); }
};

}  // namespace

std::string to_string(CurvesResidual r) { return r == CurvesResidual::rate ? "rate" : "stress"; }

CurvesResidual parse_curves_residual(const std::string& text, const std::string& where) {
  if (text == "rate") return CurvesResidual::rate;
  if (text == "stress") return CurvesResidual::stress;
  throw InputError(fmt::format(
      "{} = '{}': must be 'rate' (ln shear rate at the measured stress) or 'stress' (ln shear stress at the "
      "measured rate)",
      where, text));
}

namespace {

/// The fittable steady parameters' names, then every E8 term's phi_i and alpha.
std::vector<std::string> parameter_names(const Preset& base, bool by_default_only) {
  std::vector<std::string> n;
  for (const Parameter* row : fittable_rows(by_default_only)) n.emplace_back(row->name);
  for (std::size_t i = 0; i < base.steady.eta_B_terms.size(); ++i) {
    n.push_back(fmt::format("eta_B[{}].phi_i", i));
    n.push_back(fmt::format("eta_B[{}].alpha", i));
  }
  return n;
}

}  // namespace

std::vector<std::string> curves_parameter_names(const Preset& base) { return parameter_names(base, false); }

std::vector<std::string> curves_default_parameters(const Preset& base) { return parameter_names(base, true); }

void validate_curves_data(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                          const std::vector<double>& shear_stress, const Preset& base,
                          const CurvesFitOptions& options) {
  const std::string& w = options.where;
  if (phi.size() != shear_rate.size() || phi.size() != shear_stress.size()) {
    throw InputError(fmt::format("{}: columns phi, shear_rate, shear_stress have {}, {}, {} values: must be equal", w,
                                 phi.size(), shear_rate.size(), shear_stress.size()));
  }
  const std::size_t p = options.parameters.empty() ? curves_default_parameters(base).size() : options.parameters.size();
  if (phi.size() < p + 1) {
    throw InputError(
        fmt::format("{}: {} points for {} fitted parameters: need at least p + 1 = {}", w, phi.size(), p, p + 1));
  }
  for (std::size_t k = 0; k < phi.size(); ++k) {
    if (!(std::isfinite(phi[k]) && phi[k] > 0.0 && phi[k] < 1.0)) {
      throw InputError(
          fmt::format("{}: row {}: column 'phi' = {}: must be a finite number in (0, 1)", w, k + 1, phi[k]));
    }
    if (!(std::isfinite(shear_rate[k]) && shear_rate[k] > 0.0)) {
      throw InputError(fmt::format("{}: row {}: column 'shear_rate' = {}: must be a positive finite number [1/s]", w,
                                   k + 1, shear_rate[k]));
    }
    if (!(std::isfinite(shear_stress[k]) && shear_stress[k] > 0.0)) {
      throw InputError(fmt::format("{}: row {}: column 'shear_stress' = {}: must be a positive finite number [Pa]", w,
                                   k + 1, shear_stress[k]));
    }
  }
}

namespace {

/// Why one attempt left parameters undetermined: the message today's error gives, and which
/// parameters a non-strict fit holds (in the order they are held), each with its reason.
struct Undetermined {
  std::string message;
  std::vector<HeldParameter> hold;
};

/// One fit of the parameters `names` (the others at the base set's values): the result, or what
/// the data do not determine.
struct Attempt {
  CurvesFitResult result;
  std::optional<Undetermined> undetermined;
};

/// Ends every message that names an undetermined parameter.
constexpr const char* kUndeterminedHint =
    "fix it (leave it out of the fitted parameters, keeping the base value) or add data that depend on it (e.g. "
    "points above phi_c and above tau_star for phi_c, a_inf and eta_B; low-stress points for a_0 and phi_j)";
constexpr const char* kConvergenceHint = "start from a base set closer to the data or fit fewer parameters";

// ---- Setup: the fitted parameters, their bounds and start, the data, the Ceres problem. ----

/// The data as CurvesCost reads them: logarithms, the rows grouped by phi, the densest phi.
struct CurvesData {
  std::vector<Group> groups;
  std::vector<double> ln_rate, ln_stress;
  double max_phi = 0.0;
};

CurvesData curves_data(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                       const std::vector<double>& shear_stress) {
  CurvesData d;
  d.max_phi = *std::max_element(phi.begin(), phi.end());
  d.ln_rate.resize(phi.size());
  d.ln_stress.resize(phi.size());
  for (std::size_t k = 0; k < phi.size(); ++k) {
    d.ln_rate[k] = std::log(shear_rate[k]);
    d.ln_stress[k] = std::log(shear_stress[k]);
    auto it = std::find_if(d.groups.begin(), d.groups.end(), [&](const Group& g) { return g.phi == phi[k]; });
    if (it == d.groups.end()) {
      d.groups.push_back({phi[k], {}});
      it = d.groups.end() - 1;
    }
    it->rows.push_back(static_cast<int>(k));
  }
  return d;
}

bool is_fitted(const std::vector<Param>& params, double SteadyParams::*m) {
  return std::any_of(params.begin(), params.end(), [m](const Param& q) { return q.is(m); });
}

/// The parameters `names`, in their order; InputError for a name listed twice or unknown, and for
/// a data phi at or above the base set's phi_j when phi_j is not fitted.
std::vector<Param> fitted_parameters(const std::vector<std::string>& names, const std::vector<double>& phi,
                                     const Preset& base, const std::string& w) {
  std::vector<Param> params;
  for (const auto& n : names) {
    for (const auto& q : params) {
      if (q.name == n) throw InputError(fmt::format("{}: parameter '{}' is listed twice", w, n));
    }
    params.push_back(parse_param(n, base, w));
  }
  if (!is_fitted(params, &SteadyParams::phi_j)) {
    for (std::size_t k = 0; k < phi.size(); ++k) {
      if (!(phi[k] < base.steady.phi_j)) {
        throw InputError(fmt::format(
            "{}: row {}: column 'phi' = {}: must be below phi_j = {} of the base set (phi_j is not fitted; at "
            "phi >= phi_j there is no steady flow)",
            w, k + 1, phi[k], base.steady.phi_j));
      }
    }
  }
  return params;
}

/// Each parameter's bounds: the model's rules, then the caller's (options.bounds) intersected with
/// them; InputError for bounds of a parameter not fitted and for bounds that leave no value.
void set_bounds(std::vector<Param>& params, const Preset& base, double max_phi, const CurvesFitOptions& options,
                const std::vector<std::string>& names) {
  const std::string& w = options.where;
  const bool phi_j_fitted = is_fitted(params, &SteadyParams::phi_j),
             phi_c_fitted = is_fitted(params, &SteadyParams::phi_c);
  for (Param& q : params) {
    if (q.is(&SteadyParams::phi_j)) {
      q.lower = std::max(max_phi, phi_c_fitted ? 0.0 : base.steady.phi_c) + kStrict;
      q.upper = 1.0 - kStrict;
    } else if (q.is(&SteadyParams::phi_c)) {
      q.lower = kStrict;
      q.upper = (phi_j_fitted ? 1.0 : base.steady.phi_j) - kStrict;
    } else if (q.kind == Param::alpha) {
      q.lower = 0.0;
      q.upper = kAlphaMax;
    } else if (q.kind == Param::phi_i) {  // positive, fitted through its logarithm
      q.lower = 0.0;
      q.upper = kInf;
    } else {  // the table's range (positive scales: (0, inf), through their logarithm; Delta: [0, 1])
      const Parameter& row = parameter(Section::Steady, q.name);
      q.lower = row.lower;
      q.upper = row.upper;
    }
  }
  for (const ParameterBounds& b : options.bounds) {
    auto it = std::find_if(params.begin(), params.end(), [&](const Param& q) { return q.name == b.name; });
    if (it == params.end()) {
      throw InputError(
          fmt::format("{}: bounds for '{}', which is not fitted (fitted: {})", w, b.name, fmt::join(names, ", ")));
    }
    if (!(b.lower < b.upper) || std::isnan(b.lower) || std::isnan(b.upper)) {
      throw InputError(fmt::format("{}: bounds of '{}' = ({}, {}): the lower bound must be below the upper", w, b.name,
                                   b.lower, b.upper));
    }
    it->lower = std::max(it->lower, b.lower);
    it->upper = std::min(it->upper, b.upper);
    if (!(it->lower < it->upper)) {
      throw InputError(fmt::format("{}: bounds of '{}' = ({}, {}) leave no admissible value with the model's rules", w,
                                   b.name, b.lower, b.upper));
    }
  }
}

/// The start in internal values: the base set's values, moved into the bounds (phi_j a little
/// above the densest point).
std::vector<double> start_point(const std::vector<Param>& params, const SteadyParams& base) {
  std::vector<double> x(params.size());
  for (std::size_t i = 0; i < params.size(); ++i) {
    const Param& q = params[i];
    double v = slot(base, q);
    if (!(v > q.lower)) v = q.is(&SteadyParams::phi_j) ? std::min(q.lower + 0.01, 0.5 * (q.lower + q.upper)) : q.lower;
    if (!(v < q.upper)) v = q.upper;
    if (q.log && !(v > 0.0)) v = 1.0;
    if (q.log && q.kind == Param::phi_i && v <= 0.0) v = 1.0;
    x[i] = q.log ? std::log(v) : v;
  }
  return x;
}

/// The Ceres problem: one parameter block `x` (internal values, with the bounds of `params`) and
/// one residual block over every point (CurvesCost, central-difference Jacobians). `problem` owns
/// the returned cost functor, which reads `params` and `data`.
const CurvesCost& build_problem(ceres::Problem& problem, const std::vector<Param>& params, std::vector<double>& x,
                                const SteadyParams& base, const CurvesData& data, CurvesResidual residual) {
  const auto P = static_cast<int>(params.size());
  auto* functor = new CurvesCost{&params, base, &data.groups, &data.ln_rate, &data.ln_stress, residual, data.max_phi};
  auto* cost = new ceres::DynamicNumericDiffCostFunction<CurvesCost, ceres::CENTRAL>(functor);
  cost->AddParameterBlock(P);
  cost->SetNumResiduals(static_cast<int>(data.ln_rate.size()));
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (int i = 0; i < P; ++i) {
    const Param& q = params[static_cast<std::size_t>(i)];
    const double lo = q.log ? (q.lower > 0.0 ? std::log(q.lower) : -kInf) : q.lower;
    const double hi = q.log ? (std::isfinite(q.upper) ? std::log(q.upper) : kInf) : q.upper;
    if (std::isfinite(lo)) problem.SetParameterLowerBound(x.data(), i, lo);
    if (std::isfinite(hi)) problem.SetParameterUpperBound(x.data(), i, hi);
  }
  return *functor;
}

/// InputError unless the start has a steady state for every point, naming the first without.
void check_start(const CurvesCost& cost_fn, const std::vector<double>& x, const std::vector<double>& phi,
                 const std::vector<double>& shear_rate, const std::vector<double>& shear_stress, const Preset& base,
                 const CurvesFitOptions& options) {
  std::vector<double> r(phi.size()), model(phi.size());
  int failed = -1;
  if (cost_fn.evaluate(x.data(), r.data(), model.data(), &failed)) return;
  const std::string& w = options.where;
  if (failed < 0) {
    throw InputError(
        fmt::format("{}: the starting parameters (the base set {}, moved into the bounds) break a "
                    "rule of the model (phi_c < phi_j, phi_j > every data phi = {} ...)",
                    w, base.name, cost_fn.max_phi));
  }
  const auto f = static_cast<std::size_t>(failed);
  throw InputError(fmt::format(
      "{}: row {} (phi = {}, shear_rate = {} 1/s, shear_stress = {} Pa): the starting parameters (base set {}) "
      "have no steady state at this {}; start from a base set closer to the data{}",
      w, failed + 1, phi[f], shear_rate[f], shear_stress[f], base.name,
      options.residual == CurvesResidual::rate ? "stress" : "rate (above the fastest steady shear, e.g. DST)",
      options.residual == CurvesResidual::stress ? " or use the residual 'rate' (stress-controlled matching)" : ""));
}

// ---- Solve: Levenberg–Marquardt with bounds, and the residuals at the solution. ----

/// Solves `problem` from x; NumericalError when the cost ends non-finite. A fit that ends
/// unconverged is diagnosed after the covariance: an undetermined parameter that wanders is the
/// usual reason (named, or held so that the rest converge).
ceres::Solver::Summary solve(ceres::Problem& problem, const CurvesFitOptions& options) {
  ceres::Solver::Summary summary;
  ceres::Solve(detail::levenberg_marquardt(options.max_iterations, 1e-10, 1e-10), &problem, &summary);
  if (!std::isfinite(summary.final_cost)) {
    detail::require_convergence(summary, options.where, "curves", kConvergenceHint);
  }
  return summary;
}

/// The result's sizes, cost, iterations, residuals, model values and rms at the solution x.
CurvesFitResult fit_at_solution(const CurvesCost& cost_fn, const std::vector<double>& x,
                                const ceres::Solver::Summary& summary, int n, const std::string& w) {
  CurvesFitResult res;
  res.n = n;
  res.p = static_cast<int>(x.size());
  res.cost = summary.final_cost;
  res.iterations = static_cast<int>(summary.iterations.size());
  std::vector<double> r(static_cast<std::size_t>(n)), model(static_cast<std::size_t>(n));
  if (!cost_fn.evaluate(x.data(), r.data(), model.data(), nullptr)) {
    throw NumericalError(
        fmt::format("{}: the curves fit ended on parameters without a steady state for every point", w));
  }
  res.residuals = r;
  res.model = model;
  double ss = 0.0;
  for (double v : r) ss += v * v;
  res.rms = std::sqrt(ss / n);
  return res;
}

// ---- Covariance: the Jacobian's rank, standard errors, what the data do not determine. ----

/// The Jacobian of the residuals at the solution, in internal parameters (n x P, dense).
Eigen::MatrixXd jacobian_at_solution(ceres::Problem& problem, int n, std::size_t P) {
  double cost_at = 0.0;
  ceres::CRSMatrix crs;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost_at, nullptr, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(P));
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[static_cast<std::size_t>(row)]; k < crs.rows[static_cast<std::size_t>(row) + 1]; ++k) {
      J(row, crs.cols[static_cast<std::size_t>(k)]) = crs.values[static_cast<std::size_t>(k)];
    }
  }
  return J;
}

/// The parameters the residuals do not change with (columns of zeros in J), all held; sets
/// `scale` to the inverse column norms (1 for a column of zeros), the scaling of the rank test.
std::optional<Undetermined> flat_columns(const Eigen::MatrixXd& J, const std::vector<Param>& params,
                                         const SteadyParams& base, const std::string& w, Eigen::VectorXd& scale) {
  scale.resize(static_cast<Eigen::Index>(params.size()));
  std::vector<std::string> flat;
  std::vector<HeldParameter> flat_held;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double norm = J.col(static_cast<Eigen::Index>(i)).norm();
    if (!(norm > 0.0)) {
      flat.push_back(params[i].name);
      flat_held.push_back({params[i].name, slot(base, params[i]), "the residuals do not change with it"});
    }
    scale(static_cast<Eigen::Index>(i)) = norm > 0.0 ? 1.0 / norm : 1.0;
  }
  if (flat.empty()) return std::nullopt;
  return Undetermined{fmt::format("{}: the data do not determine {} (the residuals do not change with {}); {}", w,
                                  fmt::join(flat, ", "), flat.size() == 1 ? "it" : "them", kUndeterminedHint),
                      flat_held};
}

/// A rank-deficient scaled Jacobian (smallest singular value below kCondition times the largest):
/// the parameters in its null vector, held the one with the largest component.
std::optional<Undetermined> rank_deficiency(const Eigen::JacobiSVD<Eigen::MatrixXd>& svd,
                                            const std::vector<Param>& params, const SteadyParams& base,
                                            const std::string& w) {
  const Eigen::VectorXd& sv = svd.singularValues();
  const auto last = static_cast<Eigen::Index>(params.size()) - 1;
  if (sv(last) > kCondition * sv(0)) return std::nullopt;
  const Eigen::VectorXd v = svd.matrixV().col(last);
  std::vector<std::string> involved;
  Eigen::Index largest = 0;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    if (std::fabs(v(ii)) > 0.25) involved.push_back(params[i].name);
    if (std::fabs(v(ii)) > std::fabs(v(largest))) largest = ii;
  }
  const std::string why = fmt::format(
      "the Jacobian is rank-deficient: a combination of {} leaves every residual unchanged; condition {:.2g}",
      fmt::join(involved, ", "), sv(0) / sv(last));
  const Param& held = params[static_cast<std::size_t>(largest)];
  return Undetermined{
      fmt::format("{}: the data do not determine {} (the Jacobian is rank-deficient: a combination of {} leaves "
                  "every residual unchanged; condition {:.2g}); {}",
                  w, fmt::join(involved, ", "), involved.size() == 1 ? "this parameter" : "these parameters",
                  sv(0) / sv(last), kUndeterminedHint),
      {{held.name, slot(base, held), why}}};
}

/// Parameters determined so loosely that the value means nothing: a 1-sigma range (from the
/// internal covariance `cov`) wider than a factor of 1000 for the positive scales, 0.1 for a volume
/// fraction, 10 for an exponent, 1 for Delta; held the one furthest beyond its limit.
std::optional<Undetermined> loose_parameters(const Eigen::MatrixXd& cov, const std::vector<Param>& params,
                                             const SteadyParams& base, const std::string& w) {
  std::vector<std::string> loose;
  double loosest = 0.0;
  HeldParameter loosest_held;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double se = std::sqrt(cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)));
    const Param& q = params[i];
    const double limit = q.log                        ? std::log(1000.0)
                         : q.kind == Param::alpha     ? 10.0
                         : q.is(&SteadyParams::Delta) ? 1.0
                                                      : 0.1;
    if (!(se <= limit)) {
      const std::string range = q.log ? fmt::format("1 sigma: a factor {:.3g}", std::exp(std::min(se, 700.0)))
                                      : fmt::format("1 sigma: +- {:.3g}", se);
      loose.push_back(fmt::format("{} ({})", q.name, range));
      const double ratio = std::isnan(se) ? kInf : se / limit;
      if (loosest_held.name.empty() || ratio > loosest) {
        loosest = ratio;
        loosest_held = {
            q.name, slot(base, q),
            fmt::format("{}, beyond {}", range, q.log ? std::string("a factor 1000") : fmt::format("+- {:g}", limit))};
      }
    }
  }
  if (loose.empty()) return std::nullopt;
  return Undetermined{fmt::format("{}: the data do not determine {}; {}", w, fmt::join(loose, ", "), kUndeterminedHint),
                      {loosest_held}};
}

/// Covariance of the internal parameters from the Jacobian at the solution, D V S^-2 V^T D s^2
/// (D: the column scaling, s^2 = 2 cost/(n - p)), or what the data do not determine: flat columns,
/// a rank-deficient Jacobian, loose parameters, checked in this order.
std::optional<Undetermined> internal_covariance(ceres::Problem& problem, const std::vector<Param>& params,
                                                const SteadyParams& base, const CurvesFitResult& res,
                                                const std::string& w, Eigen::MatrixXd& cov) {
  const Eigen::MatrixXd J = jacobian_at_solution(problem, res.n, params.size());
  Eigen::VectorXd scale;
  if (auto u = flat_columns(J, params, base, w, scale)) return u;
  const Eigen::MatrixXd Js = J * scale.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
  if (auto u = rank_deficiency(svd, params, base, w)) return u;
  const double s2 = res.n > res.p ? 2.0 * res.cost / (res.n - res.p) : 0.0;
  const Eigen::MatrixXd& V = svd.matrixV();
  const Eigen::VectorXd inv_s2 = svd.singularValues().array().square().inverse();
  cov = scale.asDiagonal() * V * inv_s2.asDiagonal() * V.transpose() * scale.asDiagonal() * s2;
  return loose_parameters(cov, params, base, w);
}

/// The fitted set, the parameters with their standard errors, and the covariance and correlation
/// in natural units (the internal covariance `cov` through d value/d internal).
void store_fitted(CurvesFitResult& res, const Preset& base, const std::vector<Param>& params,
                  const std::vector<double>& x, const Eigen::MatrixXd& internal_cov) {
  const std::size_t P = params.size();
  Eigen::VectorXd dq(static_cast<Eigen::Index>(P));
  res.fitted = base;
  for (std::size_t i = 0; i < P; ++i) {
    const double value = params[i].log ? std::exp(x[i]) : x[i];
    dq(static_cast<Eigen::Index>(i)) = params[i].log ? value : 1.0;
    slot(res.fitted.steady, params[i]) = value;
  }
  const Eigen::MatrixXd cov = dq.asDiagonal() * internal_cov * dq.asDiagonal();
  res.covariance.resize(P * P);
  res.correlation.resize(P * P);
  for (std::size_t i = 0; i < P; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    res.parameters.push_back({params[i].name, slot(res.fitted.steady, params[i]), std::sqrt(cov(ii, ii))});
    for (std::size_t j = 0; j < P; ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      res.covariance[i * P + j] = cov(ii, jj);
      res.correlation[i * P + j] = cov(ii, jj) / std::sqrt(cov(ii, ii) * cov(jj, jj));
    }
  }
}

Attempt attempt_fit(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                    const std::vector<double>& shear_stress, const Preset& base, const CurvesFitOptions& options,
                    const std::vector<std::string>& names) {
  const std::string& w = options.where;
  std::vector<Param> params = fitted_parameters(names, phi, base, w);
  const CurvesData data = curves_data(phi, shear_rate, shear_stress);
  set_bounds(params, base, data.max_phi, options, names);
  std::vector<double> x = start_point(params, base.steady);
  ceres::Problem problem;
  const CurvesCost& cost_fn = build_problem(problem, params, x, base.steady, data, options.residual);
  check_start(cost_fn, x, phi, shear_rate, shear_stress, base, options);

  const ceres::Solver::Summary summary = solve(problem, options);
  Attempt out{fit_at_solution(cost_fn, x, summary, static_cast<int>(phi.size()), w), std::nullopt};

  Eigen::MatrixXd cov;
  out.undetermined = internal_covariance(problem, params, base.steady, out.result, w, cov);
  if (out.undetermined) return out;
  detail::require_convergence(summary, w, "curves", kConvergenceHint);
  store_fitted(out.result, base, params, x, cov);
  try {
    validate(out.result.fitted, w);
  } catch (const InputError& e) {
    throw NumericalError(fmt::format("the fitted parameters break a rule: {}", e.what()));
  }
  return out;
}

}  // namespace

CurvesFitResult fit_curves(const std::vector<double>& phi, const std::vector<double>& shear_rate,
                           const std::vector<double>& shear_stress, const Preset& base,
                           const CurvesFitOptions& options) {
  validate_curves_data(phi, shear_rate, shear_stress, base, options);
  std::vector<std::string> names = options.parameters.empty() ? curves_default_parameters(base) : options.parameters;
  std::vector<HeldParameter> held;
  std::string first_message;  // today's error: what the first fit, of every requested parameter, leaves undetermined
  CurvesFitOptions active = options;
  for (;;) {
    Attempt a = attempt_fit(phi, shear_rate, shear_stress, base, active, names);
    if (!a.undetermined) {
      a.result.held = held;
      return std::move(a.result);
    }
    const Undetermined& u = *a.undetermined;
    if (first_message.empty()) first_message = u.message;
    // Strict, or nothing would be left to fit: the error.
    if (options.strict || u.hold.size() >= names.size()) throw InputError(first_message);
    for (const HeldParameter& h : u.hold) {
      names.erase(std::find(names.begin(), names.end(), h.name));
      auto& b = active.bounds;
      b.erase(std::remove_if(b.begin(), b.end(), [&](const ParameterBounds& x) { return x.name == h.name; }), b.end());
      held.push_back(h);
    }
  }
}

}  // namespace oobleck::rheology
