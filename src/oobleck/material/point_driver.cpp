#include "oobleck/material/point_driver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/dilation.hpp"
#include "oobleck/rheology/eta_b.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/parameter_table.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/viscosity.hpp"

namespace oobleck::material {

void simple_shear_rates(double gamma_dot, Eigen::Matrix3d& D, Eigen::Matrix3d& W) {
  // grad v = [[0, gamma_dot, 0], [0, 0, 0], [0, 0, 0]]
  D.setZero();
  W.setZero();
  D(0, 1) = D(1, 0) = 0.5 * gamma_dot;
  W(0, 1) = 0.5 * gamma_dot;
  W(1, 0) = -0.5 * gamma_dot;
}

double default_dt(const GranularLaw& law, double phi, double shear_rate_scale, double duration) {
  const rheology::SteadyParams& s = law.steady();
  double dt = duration / 1000.0;
  if (shear_rate_scale > 0.0) dt = std::min(dt, 1e-3 / shear_rate_scale);
  if (phi < s.phi_j) {
    const double c_low = rheology::granular_viscosity(phi, s.a_0, s.phi_j - phi, s.mu_c);  // E12 branch
    dt = std::min(dt, c_low * law.eta_0() / law.G());
  }
  return std::max(dt, duration / 2e7);
}

namespace {

PointSample make_sample(const GranularLaw& law, double t, double strain, double rate, double phi,
                        const GranularState& st, const GranularUpdate& u) {
  PointSample s;
  s.time = t;
  s.strain = strain;
  s.shear_rate = rate;
  s.granular_shear_stress = u.tau_bar;
  s.granular_pressure = u.p;
  s.shear_stress = u.tau_bar + law.eta_0() * (1.0 + 2.5 * phi) * rate;
  s.sigma_xy = st.sigma(0, 1);
  s.f = st.f;
  s.phi = phi;
  s.regime = u.regime;
  s.gamma_dot_p = u.gamma_dot_p;
  s.I_v = u.I_v;
  s.I_m = u.I_m;
  s.beta = u.beta;
  s.mu_p = u.mu_p;
  s.phi_eq = u.phi_eq;
  s.iterations = u.iterations;
  return s;
}

GranularUpdate checked_update(const GranularLaw& law, GranularState& st, const Eigen::Matrix3d& D,
                              const Eigen::Matrix3d& W, double dt, double phi) {
  const GranularState before = st;
  const GranularUpdate u = law.update(st, D, W, dt, phi);
  law.require_ok(u, before, D, W, dt, phi);
  return u;
}

}  // namespace

double stress_controlled_step(const GranularLaw& law, GranularState& state, double phi, double dt, double stress,
                              GranularUpdate& update) {
  const double eta_f = law.eta_0() * (1.0 + 2.5 * phi);  // fluid part of the mixture stress (E25)
  Eigen::Matrix3d D, W;
  GranularState trial;
  GranularUpdate u;
  auto residual = [&](double rate) {
    trial = state;
    simple_shear_rates(rate, D, W);
    u = checked_update(law, trial, D, W, dt, phi);
    return u.tau_bar + eta_f * rate - stress;
  };
  double lo = 0.0, hi = stress / eta_f;
  double Rlo = residual(lo);
  if (Rlo >= 0.0) {  // the granular stress alone exceeds the target: no shear this step
    state = trial;
    update = u;
    return 0.0;
  }
  double Rhi = residual(hi);  // >= 0 since tau_bar >= 0
  // Illinois (modified regula falsi) on a bracket; residual increases with the rate.
  int side = 0;
  double rate = hi;
  for (int k = 0; k < 200; ++k) {
    rate = (Rhi - Rlo) != 0.0 ? (lo * Rhi - hi * Rlo) / (Rhi - Rlo) : 0.5 * (lo + hi);
    if (!(rate > lo && rate < hi)) rate = 0.5 * (lo + hi);
    const double R = residual(rate);
    if (std::fabs(R) <= 1e-12 * stress || (hi - lo) <= 1e-14 * hi) break;
    if (R < 0.0) {
      lo = rate;
      Rlo = R;
      if (side == -1) Rhi *= 0.5;
      side = -1;
    } else {
      hi = rate;
      Rhi = R;
      if (side == 1) Rlo *= 0.5;
      side = 1;
    }
  }
  state = trial;
  update = u;
  return rate;
}

double shear_dt(const GranularLaw& law, const ShearOptions& o) {
  if (o.dt > 0.0) return o.dt;
  const double rate_scale =
      o.stress_controlled
          ? o.shear_stress /
                (law.eta_0() * rheology::eta_r_low(law.steady(), std::min(o.phi, 0.999 * law.steady().phi_j)))
          : o.shear_rate;
  return default_dt(law, o.phi, rate_scale, o.duration);
}

ShearResult run_shear(const GranularLaw& law, const ShearOptions& o, const Progress& progress) {
  ShearResult r;
  r.dt = shear_dt(law, o);
  const long n = std::max(1L, static_cast<long>(std::ceil(o.duration / r.dt - 1e-9)));
  r.steps = n;
  GranularState st;
  st.f = o.f0;
  const int samples = std::max(o.samples, 2);
  r.samples.reserve(static_cast<std::size_t>(samples) + 2);
  Eigen::Matrix3d D, W;
  simple_shear_rates(o.shear_rate, D, W);
  double t = 0.0, strain = 0.0;
  {
    GranularUpdate u0;
    u0.tau_bar = tau_bar(st.sigma);
    u0.p = pressure(st.sigma);
    r.samples.push_back(make_sample(law, 0.0, 0.0, o.stress_controlled ? 0.0 : o.shear_rate, o.phi, st, u0));
  }
  long next_sample = 1;
  const long progress_every = std::max(1L, n / 100);
  for (long k = 1; k <= n; ++k) {
    const double dt = std::min(r.dt, o.duration - t);
    if (!(dt > 0.0)) break;
    GranularUpdate u;
    double rate = o.shear_rate;
    if (o.stress_controlled) {
      rate = stress_controlled_step(law, st, o.phi, dt, o.shear_stress, u);
    } else {
      u = checked_update(law, st, D, W, dt, o.phi);
    }
    t = (k == n) ? o.duration : t + dt;
    strain += rate * dt;
    // sample k when it crosses the next of `samples` evenly spaced times
    if (k == n || static_cast<double>(k) >= static_cast<double>(next_sample) * static_cast<double>(n) / samples) {
      r.samples.push_back(make_sample(law, t, strain, rate, o.phi, st, u));
      while (static_cast<double>(next_sample) * static_cast<double>(n) / samples <= static_cast<double>(k))
        ++next_sample;
    }
    if (progress && k % progress_every == 0)
      progress(static_cast<double>(k) / static_cast<double>(n), r.samples.back());
  }
  r.state = st;
  return r;
}

namespace {

/// c(f) = tau_bar/(eta_0 gamma_dot^p) in steady state (E3–E5) and the E24 rates, for the reduced ODE.
struct ReducedRhs {
  const GranularLaw& law;
  double phi, fm, inv_eta_B;
  void operator()(double tau, double f, double& dtau, double& df, double& rate_scale) const {
    const rheology::SteadyParams& s = law.steady();
    const double gap = rheology::phi_m_gap(s, rheology::f_jam(s, phi) - f);  // phi_m(f) - phi (E1)
    const double c = gap > 0.0 ? rheology::granular_viscosity(phi, rheology::a_of_f(s, f), gap, s.mu_c) : 0.0;
    const double gdp = gap > 0.0 ? tau / (c * law.eta_0()) : 0.0;  // jammed (phi_m <= phi): no flow
    dtau = -law.G() * gdp;
    const double x = tau / s.tau_star;
    const double K0 = law.granular().K_0;
    df = K0 * gdp * x * std::sqrt(x) * (fm - f) - K0 * (gdp + tau * inv_eta_B + s.xi_dot_eps) * f;  // E24
    rate_scale = (gap > 0.0 ? law.G() / (c * law.eta_0()) : 0.0) +
                 K0 * (gdp * (1.0 + x * std::sqrt(x)) + tau * inv_eta_B + s.xi_dot_eps);
  }
};

}  // namespace

void reduced_relax_ode(const GranularLaw& law, double phi, double span, double& tau, double& f) {
  ReducedRhs rhs{law, phi, rheology::f_m(law.steady(), phi), rheology::inverse_eta_B(law.steady(), phi)};
  const double f_top = rheology::f_upper(law.steady(), phi);
  double t = 0.0;
  long guard = 0;
  while (t < span && guard++ < 10000000) {
    double k1t, k1f, rate;
    rhs(tau, f, k1t, k1f, rate);
    double h = std::min(span - t, 0.05 / std::max(rate, 1e-300));
    // RK4 step; retried with a smaller step if it leaves the admissible set (tau >= 0, 0 <= f < f_u)
    // or changes tau by more than 20% (c(f) is very steep near f_u).
    for (int retry = 0;; ++retry) {
      double k2t, k2f, k3t, k3f, k4t, k4f, dummy;
      rhs(tau + 0.5 * h * k1t, f + 0.5 * h * k1f, k2t, k2f, dummy);
      rhs(tau + 0.5 * h * k2t, f + 0.5 * h * k2f, k3t, k3f, dummy);
      rhs(tau + h * k3t, f + h * k3f, k4t, k4f, dummy);
      const double tn = tau + h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
      const double fn = f + h / 6.0 * (k1f + 2.0 * k2f + 2.0 * k3f + k4f);
      const bool good = std::isfinite(tn) && std::isfinite(fn) && tn >= 0.0 && fn >= 0.0 && fn < f_top &&
                        std::fabs(tn - tau) <= 0.2 * tau;
      if (good || retry >= 60) {
        tau = tn;
        f = fn;
        t += h;
        break;
      }
      h *= 0.25;
    }
    if (!std::isfinite(tau) || !std::isfinite(f)) break;
  }
  if (!std::isfinite(tau) || !std::isfinite(f)) {
    throw NumericalError(
        fmt::format("reduced relaxation ODE: non-finite state (tau_bar = {}, f = {}) at phi = {}", tau, f, phi));
  }
}

double steady_rate_at_stress(const rheology::SteadyParams& s, double phi, double stress) {
  rheology::validate_phi(s, phi, "phi");
  const double fu = rheology::f_upper(s, phi);
  auto at = [&](double f) { return rheology::steady_point(s, phi, f, fu - f); };
  const double tau_lo = at(1e-12 * fu).shear_stress;
  if (!(stress > tau_lo)) {
    throw InputError(
        fmt::format("shear stress {} Pa is below the smallest steady stress {} Pa at phi = {}", stress, tau_lo, phi));
  }
  double lo = 1e-12 * fu, hi = fu * (1.0 - 1e-12);
  if (at(hi).shear_stress < stress) return at(hi).shear_rate;
  for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
    const double m = 0.5 * (lo + hi);
    (at(m).shear_stress < stress ? lo : hi) = m;
  }
  return at(0.5 * (lo + hi)).shear_rate;
}

namespace {

/// The steady state of the pre-shear of run_relax and the strain it took.
struct Preshear {
  GranularState state;
  GranularUpdate update;
  double strain = 0.0;
};

/// Pre-shear to steady state with steps of at most 2% strain; throws NumericalError if no steady
/// state with granular stress is reached.
Preshear preshear(const GranularLaw& law, const RelaxOptions& o) {
  GranularState st;
  Eigen::Matrix3d D, W;
  simple_shear_rates(o.shear_rate, D, W);
  const double rate_est =
      o.stress_controlled ? steady_rate_at_stress(law.steady(), o.phi, o.shear_stress) : o.shear_rate;
  // steps of at most 2% strain that also resolve the structure rate K_0 gamma_dot (1 + H) of E24
  auto pre_dt = [&](double tau_est) {
    const double x = tau_est / law.steady().tau_star;
    return std::max(std::min(0.02, 0.1 / (law.granular().K_0 * (1.0 + x * std::sqrt(x)))), 1e-5) / rate_est;
  };
  double dt_pre = o.stress_controlled ? pre_dt(o.shear_stress) : 0.02 / rate_est;
  GranularUpdate u;
  // Stationarity over windows of max(50 steps, 0.05 strain): relative change of tau_bar <= 1e-8 and
  // of f <= 1e-9 and of gamma_dot^p <= 1e-7 across two consecutive windows (robust to step-to-step round-off jitter).
  double win_tau = -1.0, win_f = -1.0, win_g = -1.0;
  int still_windows = 0;
  long k = 0;
  const long k_max = 4000000;
  bool steady = false;
  for (; k < k_max; ++k) {
    if (o.stress_controlled) {
      stress_controlled_step(law, st, o.phi, dt_pre, o.shear_stress, u);
    } else {
      u = checked_update(law, st, D, W, dt_pre, o.phi);
    }
    if (!o.stress_controlled && k == 200) dt_pre = std::min(dt_pre, pre_dt(u.tau_bar));
    const long window = std::max(50L, static_cast<long>(std::ceil(0.05 / (rate_est * dt_pre))));
    if (k > 200 && k % window == 0) {
      const bool still = std::fabs(u.tau_bar - win_tau) <= 1e-8 * u.tau_bar && std::fabs(st.f - win_f) <= 1e-9 &&
                         std::fabs(u.gamma_dot_p - win_g) <= 1e-7 * u.gamma_dot_p;
      win_g = u.gamma_dot_p;
      still_windows = still ? still_windows + 1 : 0;
      win_tau = u.tau_bar;
      win_f = st.f;
      if (still_windows >= 2) {
        steady = true;
        break;
      }
    }
  }
  if (!steady) {
    throw NumericalError(
        fmt::format("point relax: pre-shear (rate {} 1/s) did not reach a steady state within {} "
                    "strain (tau_bar = {} Pa, f = {}); at tau_bar comparable to G = {} Pa the "
                    "hypo-elastic rotation relaxes slowly",
                    rate_est, rate_est * dt_pre * static_cast<double>(k), u.tau_bar, st.f, law.G()));
  }
  if (u.tau_bar <= 0.0 || u.regime == GranularRegime::kSeparated) {
    throw NumericalError(
        fmt::format("point relax: the pre-sheared state carries no granular stress (regime {}, "
                    "tau_bar = {} Pa) at phi = {}",
                    regime_name(u.regime), u.tau_bar, o.phi));
  }
  return {st, u, rate_est * dt_pre * static_cast<double>(k + 1)};
}

}  // namespace

RelaxResult run_relax(const GranularLaw& law, const RelaxOptions& o, const Progress& progress) {
  RelaxResult r;
  r.G = law.G();
  r.K_0 = law.granular().K_0;
  const Preshear pre = preshear(law, o);
  GranularState st = pre.state;
  const GranularUpdate& u = pre.update;
  r.preshear_strain = pre.strain;
  r.tau_bar_0 = u.tau_bar;
  r.f_0 = st.f;
  r.p_0 = u.p;
  {
    const rheology::SteadyParams& s = law.steady();
    const double gap = rheology::phi_m_gap(s, rheology::f_jam(s, o.phi) - st.f);
    const double c = rheology::granular_viscosity(o.phi, rheology::a_of_f(s, st.f), gap, s.mu_c);
    r.relaxation_time_0 = c * law.eta_0() / law.G();
    if (!(gap > 0.0) || !std::isfinite(r.relaxation_time_0)) {
      throw NumericalError(
          fmt::format("point relax: the pre-sheared state is shear-jammed (f = {} reached f_jam, "
                      "phi_m(f) = phi): no viscous relaxation; lower the pre-shear stress",
                      st.f));
    }
  }
  // ---- relaxation: D = W = 0 ----
  const double dt0 = o.dt > 0.0 ? o.dt : r.relaxation_time_0 / 20.0;
  const Eigen::Matrix3d Z = Eigen::Matrix3d::Zero();
  double ode_tau = r.tau_bar_0, ode_f = r.f_0, t_ode = 0.0;
  const int samples = std::max(o.samples, 2);
  const double t_first = std::min(dt0, o.duration);
  auto sample_time = [&](int i) {  // log-spaced from t_first to duration
    return t_first * std::pow(o.duration / t_first, static_cast<double>(i) / (samples - 1));
  };
  r.samples.push_back({0.0, r.tau_bar_0, r.f_0, r.p_0, u.gamma_dot_p, u.regime, r.tau_bar_0, r.f_0});
  int next = 0;
  double t = 0.0;
  GranularUpdate ur;
  while (t < o.duration * (1.0 - 1e-12)) {
    double dt = std::max(dt0, o.growth * t);
    const double ts = sample_time(next);
    if (t + dt > ts) dt = ts - t;  // land on sample times
    if (t + dt > o.duration) dt = o.duration - t;
    if (!(dt > 0.0)) dt = std::max(dt0 * 1e-6, 1e-300);
    ur = checked_update(law, st, Z, Z, dt, o.phi);
    t += dt;
    if (next < samples && t >= sample_time(next) * (1.0 - 1e-12)) {
      reduced_relax_ode(law, o.phi, t - t_ode, ode_tau, ode_f);
      t_ode = t;
      r.samples.push_back({t, ur.tau_bar, st.f, ur.p, ur.gamma_dot_p, ur.regime, ode_tau, ode_f});
      while (next < samples && sample_time(next) <= t * (1.0 + 1e-12)) ++next;
      if (progress) {
        PointSample ps;
        ps.time = t;
        ps.granular_shear_stress = ur.tau_bar;
        ps.f = st.f;
        progress(t / o.duration, ps);
      }
    }
  }
  return r;
}

namespace {

/// An argument's name as `style` spells it: the CLI option ("--shear-rate") or the Python keyword ("shear_rate").
std::string arg(ArgStyle style, std::string name) {
  if (style == ArgStyle::python) return name;
  std::replace(name.begin(), name.end(), '_', '-');
  return "--" + name;
}

void check_phi(double phi, ArgStyle style) {
  if (!(std::isfinite(phi) && phi > 0.0 && phi < 1.0))
    throw InputError(fmt::format("{} = {}: must lie in (0, 1)", arg(style, "phi"), phi));
}

/// The checks shared by the shear and relax inputs: the control (one of shear rate and shear
/// stress, positive), duration and dt.
void check_control_and_time(const std::optional<double>& rate, const std::optional<double>& stress, double duration,
                            const std::optional<double>& dt, ArgStyle style) {
  if (rate && stress)
    throw InputError(
        fmt::format("{} and {}: give one of them, not both", arg(style, "shear_rate"), arg(style, "shear_stress")));
  if (!rate && !stress) {
    throw InputError(style == ArgStyle::cli ? "one of --shear-rate R or --shear-stress S is required"
                                            : "one of shear_rate or shear_stress is required");
  }
  if (rate && !(std::isfinite(*rate) && *rate > 0.0))
    throw InputError(fmt::format("{} = {}: must be positive [1/s]", arg(style, "shear_rate"), *rate));
  if (stress && !(std::isfinite(*stress) && *stress > 0.0))
    throw InputError(fmt::format("{} = {}: must be positive [Pa]", arg(style, "shear_stress"), *stress));
  if (!(std::isfinite(duration) && duration > 0.0))
    throw InputError(fmt::format("{} = {}: must be positive [s]", arg(style, "duration"), duration));
  if (dt && !(std::isfinite(*dt) && *dt > 0.0 && *dt <= duration)) {
    throw InputError(
        fmt::format("{} = {}: must lie in (0, {} = {}] [s]", arg(style, "dt"), *dt, arg(style, "duration"), duration));
  }
}

void check_samples(int samples, ArgStyle style) {
  if (samples < 2) throw InputError(fmt::format("{} = {}: must be >= 2", arg(style, "samples"), samples));
}

}  // namespace

void validate(const ShearInput& in, ArgStyle style) {
  check_phi(in.phi, style);
  check_control_and_time(in.shear_rate, in.shear_stress, in.duration, in.dt, style);
  if (!(in.f0 >= 0.0 && in.f0 <= 1.0))
    throw InputError(fmt::format("{} = {}: must lie in [0, 1]", arg(style, "f0"), in.f0));
  check_samples(in.samples, style);
}

ShearOptions shear_options(const GranularLaw& law, const ShearInput& in) {
  ShearOptions so;
  so.phi = in.phi;
  so.stress_controlled = in.shear_stress.has_value();
  so.shear_rate = so.stress_controlled ? 0.0 : in.shear_rate.value_or(0.0);
  so.shear_stress = in.shear_stress.value_or(0.0);
  so.duration = in.duration;
  so.dt = in.dt.value_or(0.0);
  so.f0 = in.f0;
  so.samples = in.samples;
  so.dt = shear_dt(law, so);
  return so;
}

void validate(const RelaxInput& in, const rheology::SteadyParams& steady, ArgStyle style) {
  check_phi(in.phi, style);
  rheology::validate_phi(steady, in.phi, arg(style, "phi"));
  check_control_and_time(in.shear_rate, in.shear_stress, in.duration, in.dt, style);
  check_samples(in.samples, style);
  for (double g : in.G) {
    if (!(std::isfinite(g) && g > 0.0))
      throw InputError(fmt::format("{} = {}: must be positive [Pa]", arg(style, "G"), g));
  }
  for (double k : in.K_0) {
    if (!(std::isfinite(k) && k > 0.0)) throw InputError(fmt::format("{} = {}: must be positive", arg(style, "K0"), k));
  }
  if (in.shear_stress) (void)steady_rate_at_stress(steady, in.phi, *in.shear_stress);  // range check
}

RelaxOptions relax_options(const RelaxInput& in) {
  RelaxOptions ro;
  ro.phi = in.phi;
  ro.stress_controlled = in.shear_stress.has_value();
  ro.shear_rate = ro.stress_controlled ? 0.0 : in.shear_rate.value_or(0.0);
  ro.shear_stress = in.shear_stress.value_or(0.0);
  ro.duration = in.duration;
  ro.dt = in.dt.value_or(0.0);
  ro.samples = in.samples;
  return ro;
}

std::span<const PointColumn> relax_columns() {
  auto column = [](double rheology::GranularParams::*member) {
    const rheology::Parameter& row = rheology::parameter(member);
    return PointColumn{row.name, row.unit};
  };
  static const std::array<PointColumn, 11> columns = {PointColumn{"case", "1"},
                                                      column(&rheology::GranularParams::G),
                                                      column(&rheology::GranularParams::K_0),
                                                      {"time", "s"},
                                                      {"granular_shear_stress", "Pa"},
                                                      {"granular_pressure", "Pa"},
                                                      {"f", "1"},
                                                      {"gamma_dot_p", "1/s"},
                                                      {"regime", ""},
                                                      {"ode_granular_shear_stress", "Pa"},
                                                      {"ode_f", "1"}};
  return columns;
}

std::array<double, 11> relax_row(std::size_t c, const RelaxResult& r, const RelaxSample& x) {
  return {static_cast<double>(c), r.G, r.K_0, x.time, x.tau_bar, x.p, x.f, x.gamma_dot_p, NAN, x.ode_tau_bar, x.ode_f};
}

std::vector<RelaxResult> run_relax_sweep(const rheology::Preset& base, const RelaxInput& in,
                                         const RelaxSweepHooks& hooks) {
  const std::vector<double> Gs = in.G.empty() ? std::vector<double>{base.granular.G} : in.G;
  const std::vector<double> K0s = in.K_0.empty() ? std::vector<double>{base.granular.K_0} : in.K_0;
  const RelaxOptions ro = relax_options(in);
  std::vector<RelaxResult> results;
  results.reserve(Gs.size() * K0s.size());
  for (double K0 : K0s) {
    for (double G : Gs) {
      rheology::Preset p = base;
      p.granular.G = G;
      p.granular.K_0 = K0;
      const GranularLaw law(p);
      const RelaxCase c{G, K0};
      results.push_back(run_relax(law, ro, hooks.start ? hooks.start(c) : Progress{}));
      if (hooks.done) hooks.done(c, results.back());
    }
  }
  return results;
}

}  // namespace oobleck::material
