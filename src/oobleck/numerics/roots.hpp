#pragma once
// Safeguarded scalar root finding used by the laws: Newton steps kept inside a shrinking
// bracket, falling back to bisection. Relative tolerances and an iteration cap; the result says
// whether it converged, so callers can report instead of silently returning garbage.
#include <cmath>

namespace oobleck::numerics {

struct RootResult {
  double x = 0.0;
  int iterations = 0;
  bool converged = false;
};

/// Find x in [lo, hi] with F(x) = 0 where F(lo) <= 0 <= F(hi) (increasing) or the reverse.
/// `fdf(x, f, df)` evaluates F and F'. Converges when the bracket or the step is below
/// rel_tol * max(|x|, abs_floor).
template <class FdF>
RootResult newton_bracketed(FdF&& fdf, double lo, double hi, double rel_tol = 1e-13, double abs_floor = 1e-300,
                            int max_iter = 100) {
  RootResult r;
  double flo = 0.0, fhi = 0.0, d = 0.0;
  fdf(lo, flo, d);
  fdf(hi, fhi, d);
  if (flo == 0.0) return {lo, 0, true};
  if (fhi == 0.0) return {hi, 0, true};
  if ((flo > 0.0) == (fhi > 0.0)) return {0.5 * (lo + hi), 0, false};
  const bool increasing = flo < 0.0;
  double x = 0.5 * (lo + hi);
  for (r.iterations = 1; r.iterations <= max_iter; ++r.iterations) {
    double fx = 0.0, dfx = 0.0;
    fdf(x, fx, dfx);
    if (fx == 0.0) return {x, r.iterations, true};
    if ((fx < 0.0) == increasing)
      lo = x;
    else
      hi = x;
    double next = (dfx != 0.0) ? x - fx / dfx : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // safeguard (also catches NaN)
    const double tol = rel_tol * std::fmax(std::fabs(next), abs_floor);
    if (std::fabs(next - x) <= tol || (hi - lo) <= tol) return {next, r.iterations, true};
    x = next;
  }
  r.x = x;
  r.converged = false;
  return r;
}

}  // namespace oobleck::numerics
