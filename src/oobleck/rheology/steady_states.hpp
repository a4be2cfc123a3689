#pragma once
// Every steady state of homogeneous simple shear at a given shear rate or mixture shear stress
// (E11, docs/equations.md): the inverse of the flow curve, branch by branch. An S-shaped curve has up to
// three states at one rate; a DST curve none above gamma_dot_DST. Used by the Python module's
// viscosity_at and by the joint flow-curve fit (fit_curves.hpp).
#include <vector>

#include "oobleck/rheology/flow_curve.hpp"

namespace oobleck::rheology {

/// Which quantity is given.
enum class Control { shear_rate, shear_stress };

/// Logistic coordinate of the structure sweep: f/f_u = 1/(1 + e^-x), f_u - f = f_u/(1 + e^x).
/// Its range [-kSweepX, kSweepX] reaches f/f_u = 4e-18 and 1 - 4e-18.
inline constexpr double kSweepX = 40.0;

/// The steady state at logistic coordinate x (see kSweepX); steady_point() without cancellation.
SteadyPoint steady_point_at_x(const SteadyParams& p, double phi, double x);

/// The flow curve at phi sampled once in x, for many inversions (the joint fit: many points per phi).
class SteadyCurve {
 public:
  /// Samples the curve at `samples` points of x in [-kSweepX, kSweepX] (no validation of phi).
  SteadyCurve(const SteadyParams& p, double phi, int samples = 128);
  /// Every state with that shear rate [1/s] or mixture shear stress [Pa], by increasing f: each
  /// sign change between samples refined by bisection in x to the resolution of doubles.
  std::vector<SteadyPoint> states_at(Control control, double value) const;
  /// The sampled state of the largest shear rate (the DST asymptote's end or the S's turning point).
  SteadyPoint fastest_sample() const;

 private:
  SteadyParams p_;
  double phi_;
  std::vector<double> x_, ln_rate_, ln_stress_;
};

/// Every steady state at phi whose shear rate [1/s] (Control::shear_rate) or mixture shear stress
/// [Pa] (Control::shear_stress) equals `value`, ordered by increasing f (the first is the
/// lowest-viscosity branch). The curve is sampled at `samples` points of x in [-kSweepX, kSweepX]
/// and every sign change refined by bisection to full precision; two states closer than the
/// sampling (a turning point) may be missed. Empty where no steady state has that value.
/// Throws InputError unless 0 < phi < phi_j and value > 0 is finite.
std::vector<SteadyPoint> steady_states_at(const SteadyParams& p, double phi, Control control, double value,
                                          int samples = 128);

}  // namespace oobleck::rheology
