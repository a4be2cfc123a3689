#pragma once
// The time-dependent granular law of the Baumgarten–Kamrin model at one material point:
// hypo-elastic Jaumann trial (E16), return map over the yield conditions E21–E23 with the flow
// rule E17–E20, and the structure update E24. Algorithm and its justification: docs/granular.md.
//
// Designed for the MPM hot loop: a GranularLaw is built once from a validated rheology::Preset
// (constants precomputed, mu_2 resolved); update() is a pure function of the point state, does no
// heap allocation and never throws. Failure (non-convergence, non-finite input or output) is
// reported in GranularUpdate::ok() / converged / finite, and describe() turns it into a
// diagnosis; the caller decides to stop (require_ok() throws NumericalError).
//
// Conventions: stress positive in tension; p = -tr(sigma)/3 (granular pressure p~, E17);
// tau_bar = |dev sigma|/sqrt(2); D, W the symmetric and skew parts of grad v_s [1/s].
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "oobleck/rheology/params.hpp"

namespace oobleck::material {

/// Which set of constraints is active at the end of the step (docs/granular.md, "Algorithm").
enum class GranularRegime : std::uint8_t {
  kElastic = 0,          ///< gamma_dot^p = 0, xi_dot_1 = xi_dot_2 = 0: f_1 <= 0, f_2 <= 0, f_3 <= 0 at the trial state
  kSeparated = 1,        ///< f_2 active (p = 0, sigma = 0, xi_dot_1 >= 0): grains out of contact (E22)
  kShear = 2,            ///< f_1 active only: plastic shear with dilatancy, p >= p_trial (E21)
  kShearCompaction = 3,  ///< f_1 and f_3 active: compacting flow, beta = 0, p <= p_trial (E21, E23)
  kCompaction = 4,       ///< f_3 active with gamma_dot^p = 0 (a loose state at rest loses its pressure)
};

/// Short lower-case name ("elastic", "separated", "shear", "shear+compaction", "compaction").
const char* regime_name(GranularRegime r);

/// What a point carries between steps (phi is not stored: MPM computes it from mass and volume).
struct GranularState {
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();  ///< effective granular stress sigma~ [Pa], tension positive
  double f = 0.0;                                   ///< micro-structure f in [0, 1] [-]
};

/// Result and diagnostics of one update (all at the end of the step).
struct GranularUpdate {
  GranularRegime regime = GranularRegime::kElastic;
  bool converged = true;          ///< every scalar solve met its tolerance within the iteration cap
  bool finite = true;             ///< inputs and outputs are finite (false => state left unchanged)
  bool jammed = false;            ///< phi >= phi_j (see GranularOptions::jammed_structure)
  int iterations = 0;             ///< scalar-solver iterations of the (final) return map
  int structure_iterations = 0;   ///< return maps evaluated by the implicit structure update (0: staggered)
  double tau_bar = 0.0;           ///< equivalent shear stress tau_bar [Pa]
  double p = 0.0;                 ///< granular pressure p~ [Pa]
  double tau_trial = 0.0;         ///< tau_bar of the elastic trial [Pa]
  double p_trial = 0.0;           ///< p~ of the elastic trial [Pa]
  double gamma_dot_p = 0.0;       ///< plastic shear rate (E17) [1/s]
  double xi_dot_1 = 0.0;          ///< separation rate (E22), >= 0 [1/s]
  double xi_dot_2 = 0.0;          ///< compaction rate (E23), <= 0 [1/s]
  double I_v = 0.0;               ///< viscous number (E19) [-]
  double I = 0.0;                 ///< inertial number (E19) [-]
  double I_m = 0.0;               ///< mixed number (E19) [-]
  double phi_m = 0.0;             ///< phi_m(f) used in the return map (E1; f_n staggered, f_{n+1} implicit) [-]
  double phi_eq = 0.0;            ///< critical-state fraction (E18) [-]
  double beta = 0.0;              ///< dilation (E18) [-]
  double mu_p = 0.0;              ///< internal friction (E20) [-]
  double f_old = 0.0;             ///< f at the start of the step [-]
  double residual = 0.0;          ///< relative residual of the final solve (0 for closed forms) [-]
  const char* message = nullptr;  ///< why ok() is false (static string), else nullptr
  bool ok() const { return converged && finite; }
};

/// What the MPM hot loop needs from one update (GranularLaw::advance): the fields of GranularUpdate
/// that do not need the E18-E20 end-state diagnostics.
struct GranularStep {
  GranularRegime regime = GranularRegime::kElastic;
  bool ok = true;            ///< GranularUpdate::ok(): converged and finite
  double gamma_dot_p = 0.0;  ///< plastic shear rate (E17) [1/s]
};

/// What the law does for phi >= phi_j (jammed: phi_m(f) <= phi for every f, no compaction).
enum class JammedStructure : std::uint8_t {
  kEvolve,    ///< E24 continues unchanged with f_m(phi) from E9 (continuous in phi; default)
  kForceOne,  ///< f is set to 1 (what the authors' code does)
};

/// How f_{n+1} (E24) is coupled to the return map.
enum class StructureUpdate : std::uint8_t {
  kStaggered,  ///< return map with f_n, then the linearly implicit E24 step (docs/granular.md)
  kImplicit,   ///< monolithic backward Euler: the return map uses f_{n+1} (scalar solve in f)
  kAuto,       ///< staggered unless dt (H' + S') > stiff_structure, then implicit (default)
};

struct GranularOptions {
  double rel_tol = 1e-12;  ///< relative tolerance of the scalar solves [-]
  int max_iter = 80;       ///< iteration cap per scalar solve
  JammedStructure jammed_structure = JammedStructure::kEvolve;
  StructureUpdate structure_update = StructureUpdate::kAuto;
  double stiff_structure = 0.5;  ///< kAuto threshold on dt (H' + S') [-] (staggering oscillates when >~ 1)
};

/// The law with its constants precomputed. Cheap to copy; thread-safe (update() is const).
class GranularLaw {
 public:
  /// Throws InputError for parameters it does not support (K_4 > 0: see docs/granular.md).
  explicit GranularLaw(const rheology::Preset& preset, GranularOptions options = {});

  /// Advance `state` over dt [s] at volume fraction phi [-] with strain rate D and spin W [1/s],
  /// using the preset's fluid viscosity eta_0.
  GranularUpdate update(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                        double phi) const {
    return update(state, D, W, dt, phi, eta_0_);
  }
  /// Same with a local fluid viscosity eta_0 [Pa s] (e.g. a temperature field).
  GranularUpdate update(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt, double phi,
                        double eta_0) const;

  /// Hot-loop form of update() (preset eta_0): the same state update, bit for bit, without the
  /// E18-E20 diagnostics of the end state (I_v, I, I_m, phi_eq, beta, mu_p) that the MPM adapter does
  /// not use. On failure call update() on the state before for the diagnosis.
  GranularStep advance(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                       double phi) const;

  /// advance() for n points at once (the MPM adapter's loop), with the same results bit for bit
  /// for every point whose step[i].ok (the same step[i] for all points): point i has stress
  /// sigma[i] and structure f[i], updated in place only when step[i].ok (advance() also stores a
  /// finite unconverged iterate), velocity gradient L[i] [1/s] (D and W are its symmetric and skew
  /// parts) and volume fraction phi[i]. Blocks of 128 points run in vector lanes phase by phase:
  /// the trials, the return map's branch, closed forms and Newton starts, the Newton solves (the
  /// f_1-only branch, the p_tr <= 0 fast path; kLanes lanes, a lane taking the next job when its
  /// own is done) and the end of step; return_map() and finish() themselves only where a lane
  /// solve fails or a point needs the implicit structure update or the forced f = 1
  /// (docs/granular.md). n may be any size.
  ///
  /// `in_plane`: the caller guarantees that the xz, yz, zx and zy entries of every sigma[i] and
  /// L[i] are zero (plane strain; zz may be anything). The trials then read and form only the
  /// other five entries: the same results (a zero entry of the stress may come out +0 where the
  /// general trials give -0). Without it, each block of 128 points whose entries are all zero
  /// (an axisymmetric flow without swirl) is found and takes the same trials.
  void advance_batch(std::int64_t n, Eigen::Matrix3d* sigma, double* f, const Eigen::Matrix3d* L, const double* phi,
                     double dt, GranularStep* step, bool in_plane = false) const;
  static constexpr int kLanes = 8;

  /// Throws NumericalError with describe() unless u.ok().
  void require_ok(const GranularUpdate& u, const GranularState& before, const Eigen::Matrix3d& D,
                  const Eigen::Matrix3d& W, double dt, double phi) const;
  /// Human-readable diagnosis of an update: the law, the state before, the inputs, what failed.
  std::string describe(const GranularUpdate& u, const GranularState& before, const Eigen::Matrix3d& D,
                       const Eigen::Matrix3d& W, double dt, double phi) const;

  // Resolved parameters (SI).
  double eta_0() const { return eta_0_; }
  double G() const { return G_; }
  double K() const { return K_; }
  double mu_1() const { return mu_1_; }
  double mu_2() const { return mu_2_; }
  const rheology::SteadyParams& steady() const { return steady_; }
  const rheology::GranularParams& granular() const { return granular_; }
  const GranularOptions& options() const { return options_; }

  /// E20 rate-independent part mu_1 + (mu_2 - mu_1)/(1 + b/I_m), with its I_m -> 0 limit.
  double mu_q(double I_m) const;

 private:
  struct ReturnMap {
    double tau = 0.0, p = 0.0, g = 0.0, xi1 = 0.0, xi2 = 0.0, residual = 0.0;
    GranularRegime regime = GranularRegime::kElastic;
    bool converged = true;
    int iterations = 0;
  };
  /// The E16 trial of a point and the E24 ingredients that depend on phi only.
  struct Trial {
    Eigen::Matrix3d s;  ///< deviator of the trial stress [Pa]
    double p_tr, tau_tr, fm, inv_eta_B;
  };
  static constexpr int kTensionIterations = 8;  ///< Newton steps of the fast path before the nested solve
  template <bool kDiagnostics>
  GranularUpdate update_impl(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                             double phi, double eta_0) const;
  /// Input checks, E16 trial, f_m and 1/eta_B; false (out says why) for invalid input.
  bool begin(const GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt, double phi,
             double eta_0, Trial& t, GranularUpdate& out) const;
  /// 1/eta_B(phi) of E8 (0 for phi >= phi_j) [1/(Pa s)]: inv_eta_B_block with every lane at phi,
  /// so that it equals the value advance_batch computes for the point, bit for bit.
  double inv_eta_B(double phi) const;
  /// 1/eta_B of E8 for numerics::kMathBlock values of phi (0 where phi >= phi_j or phi is NaN), the
  /// non-integer powers as exp(alpha log(phi_j - phi)) in vector lanes (numerics/vector_math.hpp),
  /// into r.
  void inv_eta_B_block(const double* phi, double* r) const;
  /// Structure update (E24, staggered or implicit) after the return map r at f_n, diagnostics and
  /// the final stress; writes state when the result is finite.
  template <bool kDiagnostics>
  void finish(GranularState& state, const Trial& t, ReturnMap r, double dt, double phi, double eta_0,
              GranularUpdate& out) const;
  /// E17–E23 at structure f for a given trial (p_tr, tau_tr): allocation-free, never throws.
  /// (advance_batch takes its branches, closed forms and Newton starts in lanes with the same inline
  /// functions, runs the Newton solves (the f_1-only solve and the p_tr <= 0 fast path) in lanes,
  /// and calls it where those fail.)
  ReturnMap return_map(double f, double phi, double eta_0, double dt, double p_tr, double tau_tr) const;

  rheology::SteadyParams steady_;
  rheology::GranularParams granular_;
  GranularOptions options_;
  double eta_0_, G_, K_, mu_1_, mu_2_, b_, K_3_, K_0_, d2_rho_s_, tau_star_, xi_dot_eps_;
  double phi_c_, phi_j_, a_0_, a_inf_;
  /// Per E8 term of steady_.eta_B_terms: the exponent alpha as an int when it is a whole number
  /// <= 8 (evaluated by multiplication), else kNonInteger (exp(alpha log x)).
  std::vector<int> eta_B_int_alpha_;
  static constexpr int kNonInteger = std::numeric_limits<int>::min();
};

/// Tensor helpers shared with the driver and tests.
inline double pressure(const Eigen::Matrix3d& s) { return -s.trace() / 3.0; }
inline double tau_bar(const Eigen::Matrix3d& s) {
  const Eigen::Matrix3d dev = s - (s.trace() / 3.0) * Eigen::Matrix3d::Identity();
  return std::sqrt(0.5 * dev.squaredNorm());
}

}  // namespace oobleck::material
