#pragma once
// Plain data the analysis works on, independent of the solver: a structured 2D nodal field, a
// time series, and a straight-line least-squares fit. See docs/analysis.md.
//
// Conventions
// - A GridField2D holds one value per grid node of a uniform Cartesian grid with spacing h. Node
//   (i, j) sits at x = origin_x + i h, y = origin_y + j h, for i < nx, j < ny. Values are stored
//   row-major: rows of constant j, i.e. value(i, j) = values[j * nx + i]. Axisymmetric fields
//   use x = r (radius) and y = z (axial coordinate); plane-strain fields use x, y.
// - Times are in seconds, lengths in metres, velocities in m/s unless a name says otherwise.
// - Bad inputs (empty series, mismatched sizes, non-monotone time, non-finite numbers) throw
//   oobleck::InputError with a message naming the argument and the rule it breaks.
#include <cstddef>
#include <string>
#include <vector>

namespace oobleck::analysis {

/// Nodal values on a uniform 2D grid (see the conventions above).
struct GridField2D {
  double origin_x = 0.0;       ///< x (or r) of node i = 0 [m]
  double origin_y = 0.0;       ///< y (or z) of node j = 0 [m]
  double h = 0.0;              ///< node spacing [m], same along both axes
  std::size_t nx = 0;          ///< nodes along x (r)
  std::size_t ny = 0;          ///< nodes along y (z)
  std::vector<double> values;  ///< nx * ny values, row-major (index j * nx + i)

  double x(std::size_t i) const { return origin_x + static_cast<double>(i) * h; }
  double y(std::size_t j) const { return origin_y + static_cast<double>(j) * h; }
  double x_max() const { return x(nx - 1); }
  double y_max() const { return y(ny - 1); }
  double at(std::size_t i, std::size_t j) const { return values[j * nx + i]; }
  double& at(std::size_t i, std::size_t j) { return values[j * nx + i]; }

  /// Throws InputError (naming `what`) unless h > 0, nx, ny >= 2, values.size() == nx * ny, and
  /// origin, h and every value are finite.
  void validate(const std::string& what) const;

  /// Values along the node row at height y (linear interpolation between the two bracketing
  /// rows), one per column i. Throws InputError if y lies outside [origin_y, y_max].
  std::vector<double> row_at(double y_m, const std::string& what) const;
  /// Values along the node column at abscissa x (linear interpolation between the two
  /// bracketing columns), one per row j. Throws InputError if x lies outside [origin_x, x_max].
  std::vector<double> column_at(double x_m, const std::string& what) const;
};

/// A scalar sampled in time: time[k] strictly increasing [s], value[k] in the unit its producer
/// states.
struct TimeSeries {
  std::vector<double> time;
  std::vector<double> value;

  std::size_t size() const { return time.size(); }
  /// Throws InputError (naming `what`) unless both vectors have the same size >= min_points,
  /// all entries are finite and time is strictly increasing.
  void validate(const std::string& what, std::size_t min_points = 1) const;
};

/// Ordinary least-squares fit y = slope * x + intercept.
struct LinearFit {
  double slope = 0.0;
  double intercept = 0.0;
  double r_squared = 0.0;         ///< 1 - SS_res / SS_tot (1 when SS_tot = 0 and SS_res = 0)
  double slope_stderr = 0.0;      ///< standard error of the slope, sqrt(SS_res/(n-2) / S_xx)
  double intercept_stderr = 0.0;  ///< standard error of the intercept
  std::size_t points = 0;         ///< number of points used
};

/// Least-squares straight line through (x[k], y[k]). Needs >= 2 points with distinct x; with
/// exactly 2 points the standard errors are 0 (no residual degrees of freedom) and r_squared 1.
LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y, const std::string& what = "fit_line");
/// fit_line on series.time, series.value restricted to t_begin <= t <= t_end [s].
LinearFit fit_line(const TimeSeries& series, double t_begin_s, double t_end_s, const std::string& what = "fit_line");
/// fit_line on the whole series.
LinearFit fit_line(const TimeSeries& series, const std::string& what = "fit_line");

/// The points of `series` with t_begin <= t <= t_end [s] (may be empty).
TimeSeries restrict_time(const TimeSeries& series, double t_begin_s, double t_end_s);

/// The leading part of `series` before it first comes within `margin` of `boundary`, i.e. the
/// points before the first k with |value[k] - boundary| <= margin (values approaching the
/// boundary from either side). Use it to fit a front only before it meets a wall. Throws
/// InputError if margin < 0 or not finite.
TimeSeries cut_before_boundary(const TimeSeries& series, double boundary, double margin);

/// Linear interpolation of the crossing of level `level` between (x0, g0) and (x1, g1), where g0
/// and g1 lie on opposite sides of (or on) the level; returns x0 when g0 == g1.
double interpolate_crossing(double x0, double g0, double x1, double g1, double level);

}  // namespace oobleck::analysis
