#pragma once
// Homogeneous material-point experiments with the granular law (E16–E24, docs/equations.md): simple shear at
// fixed volume, rate- or stress-controlled, and stress relaxation after cessation of steady shear
// (the SI's method for G and K_0) beside the SI's reduced ODE, with the input checks and the
// relaxation sweep over G and K_0 that `oobleck point` and oobleck.point_shear/point_relax share.
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "oobleck/material/granular.hpp"

namespace oobleck::material {

/// One recorded state of a point experiment.
struct PointSample {
  double time = 0.0;                   ///< [s]
  double strain = 0.0;                 ///< accumulated shear strain gamma [-]
  double shear_rate = 0.0;             ///< applied gamma_dot [1/s]
  double shear_stress = 0.0;           ///< mixture tau = tau_bar + eta_0 (1 + 5 phi/2) gamma_dot [Pa]
  double granular_shear_stress = 0.0;  ///< tau_bar [Pa]
  double granular_pressure = 0.0;      ///< p~ [Pa]
  double sigma_xy = 0.0;               ///< sigma~_xy [Pa]
  double f = 0.0;                      ///< structure [-]
  double phi = 0.0;                    ///< volume fraction (fixed) [-]
  GranularRegime regime = GranularRegime::kElastic;
  double gamma_dot_p = 0.0;  ///< [1/s]
  double I_v = 0.0, I_m = 0.0, beta = 0.0, mu_p = 0.0, phi_eq = 0.0;
  int iterations = 0;
};

/// Simple shear v_x = gamma_dot y at fixed volume (tr D = 0).
struct ShearOptions {
  double phi = 0.0;                ///< volume fraction [-]
  bool stress_controlled = false;  ///< false: shear_rate imposed; true: shear_stress imposed
  double shear_rate = 0.0;         ///< [1/s] (rate control)
  double shear_stress = 0.0;       ///< mixture tau [Pa] (stress control)
  double duration = 0.0;           ///< [s]
  double dt = 0.0;                 ///< [s]; <= 0 picks default_dt()
  double f0 = 0.0;                 ///< initial structure [-]
  int samples = 1000;              ///< recorded rows (evenly spaced in time, plus the first and last)
};

struct ShearResult {
  std::vector<PointSample> samples;
  GranularState state;  ///< final state
  double dt = 0.0;      ///< time step used [s]
  long steps = 0;
};

/// Progress callback: fraction done in [0, 1] and the latest sample.
using Progress = std::function<void(double, const PointSample&)>;

/// Velocity gradient of simple shear: D and W for v_x = gamma_dot y.
void simple_shear_rates(double gamma_dot, Eigen::Matrix3d& D, Eigen::Matrix3d& W);

/// Default time step: resolves the shortest elastic relaxation time eta/G of the flow (eta the
/// granular viscosity of the low-viscosity branch, E12) and 1e-3 strain per step, at most
/// duration/1000 and at least duration/2e7 (a floor that is reported by the CLI).
double default_dt(const GranularLaw& law, double phi, double shear_rate_scale, double duration);

/// The time step of a shear run: o.dt if positive, else default_dt at the run's shear-rate scale
/// (the imposed rate, or the imposed stress over the E12 viscosity eta_0 eta_r_low).
double shear_dt(const GranularLaw& law, const ShearOptions& o);

/// Run the shear experiment; throws NumericalError (describe()) if the law fails at any step.
ShearResult run_shear(const GranularLaw& law, const ShearOptions& o, const Progress& progress = {});

/// One stress-controlled step: the shear rate gamma_dot >= 0 for which the mixture shear stress
/// tau_bar_{n+1}(gamma_dot) + eta_0 (1 + 5 phi/2) gamma_dot equals `stress` (bracketed Illinois
/// solve; the law is called on copies of `state`). Returns the rate; `state`/`update` advanced.
double stress_controlled_step(const GranularLaw& law, GranularState& state, double phi, double dt, double stress,
                              GranularUpdate& update);

/// Relaxation after cessation of steady shear.
struct RelaxOptions {
  double phi = 0.0;                ///< [-]
  double shear_rate = 0.0;         ///< pre-shear rate [1/s] (rate-controlled pre-shear)
  bool stress_controlled = false;  ///< pre-shear at imposed mixture shear stress instead
  double shear_stress = 0.0;       ///< pre-shear mixture shear stress [Pa] (stress control)
  double duration = 0.0;           ///< relaxation time span after cessation [s]
  double dt = 0.0;                 ///< first relaxation step [s]; <= 0: 1/20 of the initial relaxation time
  double growth = 0.02;            ///< dt = max(dt0, growth * t) after cessation (log-time resolution)
  int samples = 200;               ///< recorded rows (log-spaced in time)
};

struct RelaxSample {
  double time = 0.0;
  double tau_bar = 0.0, f = 0.0, p = 0.0, gamma_dot_p = 0.0;
  GranularRegime regime = GranularRegime::kElastic;
  double ode_tau_bar = 0.0, ode_f = 0.0;  ///< the SI reduced ODE at the same time
};

struct RelaxResult {
  double G = 0.0, K_0 = 0.0;
  double tau_bar_0 = 0.0, f_0 = 0.0, p_0 = 0.0;  ///< steady state before cessation
  double relaxation_time_0 = 0.0;                ///< c(f_0) eta_0/G [s]
  double preshear_strain = 0.0;
  std::vector<RelaxSample> samples;
};

/// Closed-form steady shear rate at mixture shear stress `stress` (E11 swept in f; tau(f) is
/// increasing), used to size pre-shear steps. Throws InputError if stress is out of range.
double steady_rate_at_stress(const rheology::SteadyParams& s, double phi, double stress);

/// Pre-shear to steady state (coarse steps: the backward-Euler return map has the exact steady
/// state for any dt), then D = W = 0. `law` carries G and K_0.
RelaxResult run_relax(const GranularLaw& law, const RelaxOptions& o, const Progress& progress = {});

/// How the input checks name the arguments in their messages: as the CLI's options
/// ("--shear-rate") or as the Python module's keyword arguments ("shear_rate").
enum class ArgStyle { cli, python };

/// The inputs of a point shear run as a front end received them, before any check; an empty
/// optional is an argument not given.
struct ShearInput {
  double phi = NAN;
  std::optional<double> shear_rate, shear_stress;
  double duration = NAN;
  std::optional<double> dt;
  double f0 = 0.0;
  int samples = 1000;
};

/// Throws InputError naming the first bad argument and its rule (e.g. "--dt = 2: must lie in
/// (0, --duration = 1] [s]"): 0 < phi < 1, exactly one of shear_rate and shear_stress, each
/// positive, duration > 0, 0 < dt <= duration, 0 <= f0 <= 1, samples >= 2.
void validate(const ShearInput& in, ArgStyle style);

/// The run_shear options of a checked input, the time step resolved by shear_dt.
ShearOptions shear_options(const GranularLaw& law, const ShearInput& in);

/// The inputs of a relaxation sweep (one run_relax per pair of G and K_0) before any check.
struct RelaxInput {
  double phi = NAN;
  std::optional<double> shear_rate, shear_stress;  ///< the pre-shear
  double duration = NAN;
  std::optional<double> dt;
  int samples = 200;
  std::vector<double> G, K_0;  ///< the sweep's moduli [Pa] and rate factors; empty: the parameter set's
};

/// Throws InputError naming the first bad argument and its rule: 0 < phi < 1 and phi < phi_j,
/// the pre-shear as in validate(ShearInput), duration, dt and samples likewise, every G and K_0
/// positive, and a pre-shear stress within the steady flow curve (steady_rate_at_stress).
void validate(const RelaxInput& in, const rheology::SteadyParams& steady, ArgStyle style);

/// The run_relax options of a checked input.
RelaxOptions relax_options(const RelaxInput& in);

/// One case of a relaxation sweep: the parameter set with these G and K_0.
struct RelaxCase {
  double G = 0.0, K_0 = 0.0;
};

/// Optional hooks of run_relax_sweep: `start` gives the progress callback of a case before it
/// runs, `done` sees its result.
struct RelaxSweepHooks {
  std::function<Progress(const RelaxCase&)> start;
  std::function<void(const RelaxCase&, const RelaxResult&)> done;
};

/// run_relax of a checked input for each K_0 (outer) and G (inner) of the sweep on `base`; the
/// results in that order.
std::vector<RelaxResult> run_relax_sweep(const rheology::Preset& base, const RelaxInput& in,
                                         const RelaxSweepHooks& hooks = {});

/// One column of a point run's table (the CLI's CSV, the Python module's dict): its name and SI
/// unit ("1": dimensionless; empty: a text column).
struct PointColumn {
  std::string_view name;
  std::string_view unit;
};

/// The columns of a relaxation sweep's table, in order: case, G, K_0 (named and united as the
/// parameter table has them), time, granular_shear_stress, granular_pressure, f, gamma_dot_p,
/// regime (text), ode_granular_shear_stress, ode_f.
std::span<const PointColumn> relax_columns();

/// Sample x of case c (its result r) in relax_columns' order; the text column (regime) is NaN here
/// (regime_name(x.regime) gives its text).
std::array<double, 11> relax_row(std::size_t c, const RelaxResult& r, const RelaxSample& x);

/// The SI's reduced relaxation ODE (docs/granular.md, "Notes on the SI"): d tau_bar/dt = -G gamma_dot^p,
/// gamma_dot^p = tau_bar/(c(f) eta_0) with c(f) = mu_1 eta_n + (5/2) phi^2/(phi_m - phi) (E3–E5),
/// f from E24. Integrated with classical RK4 on substeps of 1/20 of the fastest time scale.
/// Advances (tau_bar, f) from t to t + span.
void reduced_relax_ode(const GranularLaw& law, double phi, double span, double& tau_bar, double& f);

}  // namespace oobleck::material
