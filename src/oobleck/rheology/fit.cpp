#include "oobleck/rheology/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <glog/logging.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/dilation.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/least_squares.hpp"
#include "oobleck/rheology/parameter_table.hpp"

namespace oobleck::rheology {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Strict inequalities (phi_j > max phi, ...) become Ceres' inclusive bounds shifted by this.
constexpr double kStrict = 1e-7;
/// Largest alpha_i [-] the dst fit may reach (no preset comes near: the largest is 12).
constexpr double kAlphaMax = 60.0;
/// Smallest dilation parameter a [-] the fit may reach (a > 0).
constexpr double kAMin = 1e-8;

// ---------------------------------------------------------------------------------------------
// Cost functors (log residuals). The closed forms are written again as templates because Ceres
// differentiates them with Jets; fit_model_value() evaluates the library's double versions
// (flow_curve.hpp) and the tests check that both agree.

/// E12 / E13: eta_r = 1 + (5/2) phi phi_m/(phi_m - phi) + 2 mu_c (a phi/(phi_m - phi))^2 with
/// (a, phi_m) = (a_0, phi_j) on the low branch and (a_inf, phi_c) on the high branch.
/// x[0] = a [-], x[1] = phi_m [-]; residual ln(eta_r model) - ln(eta_r data).
struct ViscosityResidual {
  double phi;            ///< [-]
  double ln_eta_r_data;  ///< ln of the measured relative viscosity
  double mu_c;           ///< [-] fixed

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    const T gap = x[1] - phi;  // phi_m - phi
    if (!(gap > T(0.0))) return false;
    const T r = x[0] * phi / gap;
    const T eta_r = 1.0 + 2.5 * phi * x[1] / gap + 2.0 * mu_c * r * r;
    residual[0] = log(eta_r) - ln_eta_r_data;
    return true;
  }
};

/// E14 with E8: ln gamma_dot_DST = ln(tau*/eta_0) - (1/3) ln(2 mu_c) - (2/3) ln(a(f_m) phi/(phi_j - phi))
///   + (2/3) ln(eta_0 sum_i phi_i (phi_j - phi)^alpha_i).
/// Everything but the sum is fixed by the base set and folded into `offset` (minus ln data), so
/// the residual is offset + (2/3) ln sum_i exp(ln phi_i + alpha_i ln(phi_j - phi)).
/// Parameter block i = [ln(phi_i / (1/(Pa s))), alpha_i].
struct DstResidual {
  double ln_gap;  ///< ln(phi_j - phi)
  double offset;  ///< the fixed part of ln(model) minus ln(data)
  int terms;

  template <typename T>
  bool operator()(T const* const* x, T* residual) const {
    // log-sum-exp, shifted by the largest exponent so no term overflows or underflows alone.
    T largest = x[0][0] + x[0][1] * ln_gap;
    for (int i = 1; i < terms; ++i) {
      const T e = x[i][0] + x[i][1] * ln_gap;
      if (e > largest) largest = e;
    }
    T sum = T(0.0);
    for (int i = 0; i < terms; ++i) sum += exp(x[i][0] + x[i][1] * ln_gap - largest);
    residual[0] = offset + (2.0 / 3.0) * (largest + log(sum));
    return true;
  }
};

// ---------------------------------------------------------------------------------------------
// Helpers.

/// Least-squares line y = c0 + c1 x; returns false when the x are all equal.
bool fit_line(const std::vector<double>& x, const std::vector<double>& y, double& c0, double& c1) {
  const auto n = static_cast<double>(x.size());
  if (x.size() < 2) return false;
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    sxx += (x[k] - mx) * (x[k] - mx);
    sxy += (x[k] - mx) * (y[k] - my);
  }
  if (!(sxx > 0.0)) return false;
  c1 = sxy / sxx;
  c0 = my - c1 * mx;
  return true;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

ceres::Solver::Options solver_options(const FitOptions& options) {
  return detail::levenberg_marquardt(options.max_iterations, 1e-12, 1e-12);
}

void require_convergence(const ceres::Solver::Summary& s, FitKind kind, const FitOptions& options) {
  detail::require_convergence(s, options.where, to_string(kind),
                              "check that the data follow the model's asymptote (E12/E13/E14) and that the base "
                              "parameter set suits them");
}

/// Covariance of the listed blocks (row-major, full matrix over the concatenated blocks),
/// unscaled ((J^T J)^-1); empty when the Jacobian is rank-deficient.
std::vector<double> covariance(ceres::Problem& problem, const std::vector<const double*>& blocks, int size) {
  ceres::Covariance::Options o;
  o.algorithm_type = ceres::DENSE_SVD;  // reports rank deficiency instead of failing obscurely
  o.num_threads = 1;
  ceres::Covariance cov(o);
  // Ceres logs a rank-deficient Jacobian through glog (LOG(ERROR)) besides returning false; the
  // caller reports it (NaN standard errors), so silence glog for the call. Fits are serial.
  struct QuietGlog {
    int saved = FLAGS_minloglevel;
    QuietGlog() { FLAGS_minloglevel = google::GLOG_FATAL; }
    ~QuietGlog() { FLAGS_minloglevel = saved; }
  } quiet;
  std::vector<std::pair<const double*, const double*>> pairs;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t j = i; j < blocks.size(); ++j) pairs.emplace_back(blocks[i], blocks[j]);
  }
  if (!cov.Compute(pairs, &problem)) return {};
  std::vector<double> m(static_cast<std::size_t>(size * size));
  if (!cov.GetCovarianceMatrix(blocks, m.data())) return {};
  return m;
}

void fill_statistics(FitResult& r, const ceres::Solver::Summary& s) {
  r.cost = s.final_cost;
  r.residual_variance = 2.0 * s.final_cost / (r.n - r.p);
  r.iterations = static_cast<int>(s.iterations.size());
  r.solver_report = s.BriefReport();
}

// ---------------------------------------------------------------------------------------------
// low / high: (a, phi_m) of E12 / E13.

/// Initial guess from the data alone. Where the friction term of E12/E13 dominates,
/// phi/sqrt(eta_r - 1 - 5 phi/2) ~ (phi_m - phi)/(a sqrt(2 mu_c)) is linear in phi: its root is
/// phi_m. With phi_m fixed, each point gives a by inverting E12/E13 exactly; take the median.
void viscosity_guess(const std::vector<double>& phi, const std::vector<double>& eta_r, double mu_c, double phi_m_lo,
                     double phi_m_hi, double& a, double& phi_m) {
  std::vector<double> x, z;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const double excess = eta_r[k] - 1.0 - 2.5 * phi[k];
    if (excess > 0.0) {
      x.push_back(phi[k]);
      z.push_back(phi[k] / std::sqrt(excess));
    }
  }
  double c0 = 0.0, c1 = 0.0;
  phi_m = kNaN;
  if (fit_line(x, z, c0, c1) && c1 < 0.0) phi_m = -c0 / c1;
  const double span = phi_m_hi - phi_m_lo;
  if (!std::isfinite(phi_m) || phi_m <= phi_m_lo || phi_m >= phi_m_hi) {
    // Out of the admissible range: start a little above the densest point instead.
    phi_m = phi_m_lo + std::min(0.02, 0.25 * span);
  }
  std::vector<double> a_k;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const double gap = phi_m - phi[k];
    const double friction = eta_r[k] - 1.0 - 2.5 * phi[k] * phi_m / gap;  // 2 mu_c (a phi/gap)^2
    if (friction > 0.0) a_k.push_back(std::sqrt(friction / (2.0 * mu_c)) * gap / phi[k]);
  }
  a = a_k.empty() ? 1.0 : median(a_k);
}

FitResult fit_viscosity(FitKind kind, const std::vector<double>& phi, const std::vector<double>& eta_r,
                        const SteadyParams& base, const FitOptions& options) {
  const double phi_max = *std::max_element(phi.begin(), phi.end());
  double lo = 0.0, hi = 0.0;   // admissible phi_m
  if (kind == FitKind::low) {  // phi_j > max data phi, phi_j > base phi_c, phi_j < 1
    lo = std::max(phi_max, base.phi_c) + kStrict;
    hi = 1.0 - kStrict;
  } else {  // phi_c > max data phi, phi_c < base phi_j
    lo = phi_max + kStrict;
    hi = base.phi_j - kStrict;
  }
  if (!(lo < hi)) {
    throw InputError(
        fmt::format("{}: no admissible {}: it must exceed the largest data phi = {}{} and stay below {}", options.where,
                    parameter(kind == FitKind::low ? &SteadyParams::phi_j : &SteadyParams::phi_c).name, phi_max,
                    kind == FitKind::low ? fmt::format(" and the base phi_c = {}", base.phi_c) : "",
                    kind == FitKind::low ? "1" : fmt::format("the base phi_j = {}", base.phi_j)));
  }
  double x[2];
  viscosity_guess(phi, eta_r, base.mu_c, lo, hi, x[0], x[1]);
  x[0] = std::max(x[0], 2.0 * kAMin);

  ceres::Problem problem;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ViscosityResidual, 1, 2>(
                                 new ViscosityResidual{phi[k], std::log(eta_r[k]), base.mu_c}),
                             nullptr, x);
  }
  problem.SetParameterLowerBound(x, 0, kAMin);
  problem.SetParameterLowerBound(x, 1, lo);
  problem.SetParameterUpperBound(x, 1, hi);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(options), &problem, &summary);
  require_convergence(summary, kind, options);

  FitResult r;
  r.kind = kind;
  r.n = static_cast<int>(phi.size());
  r.p = 2;
  fill_statistics(r, summary);
  const auto cov = covariance(problem, {x}, 2);
  r.covariance_ok = !cov.empty();
  const double se_a = r.covariance_ok ? std::sqrt(cov[0] * r.residual_variance) : kNaN;
  const double se_phi = r.covariance_ok ? std::sqrt(cov[3] * r.residual_variance) : kNaN;
  r.params = base;
  if (kind == FitKind::low) {
    r.params.a_0 = x[0];
    r.params.phi_j = x[1];
    r.parameters = {{std::string(parameter(&SteadyParams::a_0).name), x[0], se_a},
                    {std::string(parameter(&SteadyParams::phi_j).name), x[1], se_phi}};
  } else {
    r.params.a_inf = x[0];
    r.params.phi_c = x[1];
    r.parameters = {{std::string(parameter(&SteadyParams::a_inf).name), x[0], se_a},
                    {std::string(parameter(&SteadyParams::phi_c).name), x[1], se_phi}};
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// dst: (phi_i, alpha_i) of E8 through E14.

/// Offset of DstResidual: the fixed part of ln gamma_dot_DST (E14) minus ln(data).
double dst_offset(const SteadyParams& base, double phi, double rate) {
  const double gap = base.phi_j - phi;
  const double a_fm = a_of_f(base, f_m(base, phi));  // E2 at f_m from E9
  return std::log(base.tau_star / base.eta_0) - std::log(2.0 * base.mu_c) / 3.0 -
         (2.0 / 3.0) * std::log(a_fm * phi / gap) + (2.0 / 3.0) * std::log(base.eta_0) - std::log(rate);
}

/// Initial guesses from the data alone. E14 inverted point by point gives
/// y_k = ln(1/eta_B) = ln sum_i phi_i gap^alpha_i at x_k = ln gap. Sorted by gap, the points are
/// cut into `terms` runs; a straight line through each run starts one term (the run at the
/// largest gaps starts the steepest). Several cut positions give several starts.
std::vector<std::vector<double>> dst_guesses(const std::vector<double>& x, const std::vector<double>& y, int terms) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return x[i] > x[j]; });
  const std::vector<double> skews = terms == 1 ? std::vector<double>{1.0} : std::vector<double>{1.0, 0.6, 1.6};
  std::vector<std::vector<double>> starts;
  for (double skew : skews) {
    std::vector<double> start;
    for (int i = 0; i < terms; ++i) {
      const auto cut = [&](int j) {
        return static_cast<std::size_t>(std::lround(std::pow(double(j) / terms, skew) * double(x.size())));
      };
      std::vector<double> xs, ys;
      for (std::size_t k = cut(i); k < cut(i + 1); ++k) {
        xs.push_back(x[order[k]]);
        ys.push_back(y[order[k]]);
      }
      double c0 = 0.0, c1 = 0.0;
      if (!fit_line(xs, ys, c0, c1)) {
        c1 = 1.0;
        c0 = xs.empty() ? 0.0 : ys[0] - xs[0];
      }
      c1 = std::clamp(c1, 0.0, kAlphaMax);
      if (!xs.empty() && c1 != 0.0) {  // keep the line through the run's mean after clamping
        c0 = std::accumulate(ys.begin(), ys.end(), 0.0) / double(ys.size()) -
             c1 * std::accumulate(xs.begin(), xs.end(), 0.0) / double(xs.size());
      }
      start.push_back(c0);
      start.push_back(c1);
    }
    starts.push_back(std::move(start));
  }
  return starts;
}

FitResult fit_dst(const std::vector<double>& phi, const std::vector<double>& rate, const SteadyParams& base, int terms,
                  const FitOptions& options) {
  std::vector<double> ln_gap(phi.size()), offset(phi.size()), ln_inv_eta_B(phi.size());
  for (std::size_t k = 0; k < phi.size(); ++k) {
    ln_gap[k] = std::log(base.phi_j - phi[k]);
    offset[k] = dst_offset(base, phi[k], rate[k]);
    ln_inv_eta_B[k] = -1.5 * offset[k];  // residual 0 <=> (2/3) ln sum = -offset
  }

  struct Attempt {
    std::vector<double> x;  // [ln phi_0, alpha_0, ln phi_1, alpha_1, ...]
    ceres::Solver::Summary summary;
  };
  std::unique_ptr<Attempt> best;
  std::unique_ptr<ceres::Problem> best_problem;
  ceres::Solver::Summary last;
  for (auto& start : dst_guesses(ln_gap, ln_inv_eta_B, terms)) {
    auto attempt = std::make_unique<Attempt>();
    attempt->x = std::move(start);
    auto problem = std::make_unique<ceres::Problem>();
    std::vector<double*> blocks;
    blocks.reserve(static_cast<std::size_t>(terms));
    for (int i = 0; i < terms; ++i) blocks.push_back(attempt->x.data() + 2 * i);
    for (std::size_t k = 0; k < phi.size(); ++k) {
      auto* cf = new ceres::DynamicAutoDiffCostFunction<DstResidual, 4>(new DstResidual{ln_gap[k], offset[k], terms});
      for (int i = 0; i < terms; ++i) cf->AddParameterBlock(2);
      cf->SetNumResiduals(1);
      problem->AddResidualBlock(cf, nullptr, blocks);
    }
    for (double* b : blocks) {
      problem->SetParameterLowerBound(b, 1, 0.0);  // alpha_i >= 0
      problem->SetParameterUpperBound(b, 1, kAlphaMax);
    }
    ceres::Solve(solver_options(options), problem.get(), &attempt->summary);
    last = attempt->summary;
    if (attempt->summary.termination_type != ceres::CONVERGENCE) continue;
    if (!best || attempt->summary.final_cost < best->summary.final_cost) {
      best = std::move(attempt);
      best_problem = std::move(problem);
    }
  }
  if (!best) require_convergence(last, FitKind::dst, options);  // throws

  FitResult r;
  r.kind = FitKind::dst;
  r.n = static_cast<int>(phi.size());
  r.p = 2 * terms;
  fill_statistics(r, best->summary);
  std::vector<const double*> blocks;
  blocks.reserve(static_cast<std::size_t>(terms));
  for (int i = 0; i < terms; ++i) blocks.push_back(best->x.data() + 2 * i);
  const auto cov = covariance(*best_problem, blocks, r.p);
  r.covariance_ok = !cov.empty();
  auto se = [&](int j) {
    const auto jj = static_cast<std::size_t>(j);  // the diagonal entry (j, j) of the p x p covariance
    return r.covariance_ok ? std::sqrt(cov[jj * static_cast<std::size_t>(r.p) + jj] * r.residual_variance) : kNaN;
  };
  // Canonical order: steepest term first (as in the presets).
  std::vector<int> idx(static_cast<std::size_t>(terms));
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](int i, int j) { return best->x[2 * i + 1] > best->x[2 * j + 1]; });
  r.params = base;
  r.params.eta_B_terms.clear();
  for (std::size_t n = 0; n < idx.size(); ++n) {
    const int i = idx[n];
    const double phi_i = std::exp(best->x[2 * i]);
    const double alpha = best->x[2 * i + 1];
    r.params.eta_B_terms.push_back({phi_i, alpha});
    // phi_i = exp(ln phi_i): its standard error is phi_i times that of ln phi_i (delta method).
    r.parameters.push_back({fmt::format("eta_B[{}].phi_i", n), phi_i, phi_i * se(2 * i)});
    r.parameters.push_back({fmt::format("eta_B[{}].alpha", n), alpha, se(2 * i + 1)});
  }
  return r;
}

}  // namespace

std::string to_string(FitKind kind) {
  switch (kind) {
    case FitKind::low: return "low";
    case FitKind::high: return "high";
    case FitKind::dst: return "dst";
  }
  return "?";
}

FitKind parse_fit_kind(const std::string& text, const std::string& where) {
  if (text == "low") return FitKind::low;
  if (text == "high") return FitKind::high;
  if (text == "dst") return FitKind::dst;
  throw InputError(
      fmt::format("{} = '{}': must be one of low (a_0, phi_j from minimum viscosities, E12), "
                  "high (a_inf, phi_c from plateau viscosities, E13), dst (eta_B terms from DST "
                  "rates, E14)",
                  where, text));
}

int fit_parameter_count(FitKind kind, const SteadyParams& base, const FitOptions& options) {
  if (kind != FitKind::dst) return 2;
  if (options.terms > 0) return 2 * options.terms;
  return 2 * std::max<int>(1, static_cast<int>(base.eta_B_terms.size()));
}

void validate_fit_data(FitKind kind, const std::vector<double>& phi, const std::vector<double>& values,
                       const SteadyParams& base, const FitOptions& options) {
  const std::string& w = options.where;
  const char* value_name = kind == FitKind::dst ? "shear_rate_dst" : "relative viscosity";
  if (phi.size() != values.size()) {
    throw InputError(fmt::format("{}: {} values of phi but {} of {}", w, phi.size(), values.size(), value_name));
  }
  if (kind == FitKind::dst && (options.terms < 0 || options.terms > 8)) {
    throw InputError(fmt::format("--terms = {}: must lie in 1..8 (0: as many as the base set has)", options.terms));
  }
  const int p = fit_parameter_count(kind, base, options);
  if (static_cast<int>(phi.size()) < p + 1) {
    throw InputError(
        fmt::format("{}: {} data points, but the {} fit has {} parameters: need at least {} points "
                    "(n >= parameters + 1)",
                    w, phi.size(), to_string(kind), p, p + 1));
  }
  const double ps = phi_star(base);
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const double f = phi[k], v = values[k];
    if (!(std::isfinite(f) && f > 0.0 && f < 1.0)) {
      throw InputError(fmt::format("{}: point {}: phi = {}: must lie in (0, 1)", w, k + 1, f));
    }
    if (!(std::isfinite(v) && v > 0.0)) {
      throw InputError(fmt::format("{}: point {}: {} = {}: must be positive", w, k + 1, value_name, v));
    }
    if (kind == FitKind::high && !(f < base.phi_j)) {
      throw InputError(
          fmt::format("{}: point {}: phi = {}: plateau data need phi < phi_j = {} of the base set "
                      "(E13 holds for phi < phi_c < phi_j)",
                      w, k + 1, f, base.phi_j));
    }
    if (kind == FitKind::dst && !(f >= base.phi_c && f <= ps && f < base.phi_j)) {
      throw InputError(
          fmt::format("{}: point {}: phi = {}: E14 applies only for phi_c <= phi <= phi* and "
                      "phi < phi_j (base set: phi_c = {}, phi* = {}, phi_j = {}); fit phi_c and "
                      "phi_j first (--kind high, --kind low)",
                      w, k + 1, f, base.phi_c, ps, base.phi_j));
    }
  }
}

FitResult fit(FitKind kind, const std::vector<double>& phi, const std::vector<double>& values, const SteadyParams& base,
              const FitOptions& options) {
  validate_fit_data(kind, phi, values, base, options);
  FitResult r = kind == FitKind::dst ? fit_dst(phi, values, base, fit_parameter_count(kind, base, options) / 2, options)
                                     : fit_viscosity(kind, phi, values, base, options);
  // RMS of the log residuals, evaluated with the library's closed forms E12/E13/E14.
  double sum = 0.0;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const double d = std::log(fit_model_value(kind, r.params, phi[k])) - std::log(values[k]);
    sum += d * d;
  }
  r.rms = std::sqrt(sum / static_cast<double>(phi.size()));
  if (!std::isfinite(r.rms)) {
    throw NumericalError(fmt::format("{}: the {} fit produced a non-finite residual", options.where, to_string(kind)));
  }
  return r;
}

double fit_model_value(FitKind kind, const SteadyParams& params, double phi) {
  switch (kind) {
    case FitKind::low: return phi < params.phi_j ? eta_r_low(params, phi) : kNaN;    // E12
    case FitKind::high: return phi < params.phi_c ? eta_r_high(params, phi) : kNaN;  // E13
    case FitKind::dst: return shear_rate_dst(params, phi).value_or(kNaN);            // E14
  }
  return kNaN;
}

}  // namespace oobleck::rheology
