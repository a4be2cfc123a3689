#include "oobleck/analysis/data.hpp"

#include <cmath>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

void GridField2D::validate(const std::string& what) const {
  if (!(std::isfinite(h) && h > 0.0))
    throw InputError(fmt::format("{}: grid spacing h = {} must be finite and > 0", what, h));
  if (!std::isfinite(origin_x) || !std::isfinite(origin_y))
    throw InputError(fmt::format("{}: grid origin ({}, {}) must be finite", what, origin_x, origin_y));
  if (nx < 2 || ny < 2)
    throw InputError(fmt::format("{}: grid must have at least 2 x 2 nodes, got {} x {}", what, nx, ny));
  if (values.size() != nx * ny)
    throw InputError(
        fmt::format("{}: {} values for a {} x {} grid (expected nx * ny = {})", what, values.size(), nx, ny, nx * ny));
  for (std::size_t k = 0; k < values.size(); ++k)
    if (!std::isfinite(values[k]))
      throw InputError(
          fmt::format("{}: value at node (i = {}, j = {}) is not finite ({})", what, k % nx, k / nx, values[k]));
}

namespace {
// Index of the lower bracketing node and the weight of the upper one for coordinate c on an axis
// with `n` nodes starting at `origin` with spacing h. Requires origin <= c <= origin + (n-1) h.
void bracket(double c, double origin, double h, std::size_t n, std::size_t& lo, double& w) {
  const double s = (c - origin) / h;
  const double last = static_cast<double>(n - 1);
  if (s >= last) {
    lo = n - 2;
    w = 1.0;
    return;
  }
  const double fl = std::floor(s < 0.0 ? 0.0 : s);
  lo = static_cast<std::size_t>(fl);
  w = s - fl;
}
}  // namespace

std::vector<double> GridField2D::row_at(double y_m, const std::string& what) const {
  const double tol = 1e-9 * h;
  if (!std::isfinite(y_m) || y_m < origin_y - tol || y_m > y_max() + tol)
    throw InputError(fmt::format("{}: height y = {} m lies outside the grid [{}, {}] m", what, y_m, origin_y, y_max()));
  std::size_t j = 0;
  double w = 0.0;
  bracket(y_m, origin_y, h, ny, j, w);
  std::vector<double> out(nx);
  for (std::size_t i = 0; i < nx; ++i) out[i] = (1.0 - w) * at(i, j) + w * at(i, j + 1);
  return out;
}

std::vector<double> GridField2D::column_at(double x_m, const std::string& what) const {
  const double tol = 1e-9 * h;
  if (!std::isfinite(x_m) || x_m < origin_x - tol || x_m > x_max() + tol)
    throw InputError(
        fmt::format("{}: abscissa x = {} m lies outside the grid [{}, {}] m", what, x_m, origin_x, x_max()));
  std::size_t i = 0;
  double w = 0.0;
  bracket(x_m, origin_x, h, nx, i, w);
  std::vector<double> out(ny);
  for (std::size_t j = 0; j < ny; ++j) out[j] = (1.0 - w) * at(i, j) + w * at(i + 1, j);
  return out;
}

void TimeSeries::validate(const std::string& what, std::size_t min_points) const {
  if (time.size() != value.size())
    throw InputError(fmt::format("{}: {} times but {} values (sizes must match)", what, time.size(), value.size()));
  if (time.size() < min_points)
    throw InputError(fmt::format("{}: {} samples, at least {} needed", what, time.size(), min_points));
  for (std::size_t k = 0; k < time.size(); ++k) {
    if (!std::isfinite(time[k]) || !std::isfinite(value[k]))
      throw InputError(fmt::format("{}: sample {} (t = {}, value = {}) is not finite", what, k, time[k], value[k]));
    if (k > 0 && !(time[k] > time[k - 1]))
      throw InputError(
          fmt::format("{}: time must be strictly increasing, but t[{}] = {} s <= "
                      "t[{}] = {} s",
                      what, k, time[k], k - 1, time[k - 1]));
  }
}

LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y, const std::string& what) {
  if (x.size() != y.size()) throw InputError(fmt::format("{}: {} x values but {} y values", what, x.size(), y.size()));
  const std::size_t n = x.size();
  if (n < 2) throw InputError(fmt::format("{}: {} points, a line needs at least 2", what, n));
  double mx = 0.0, my = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(x[k]) || !std::isfinite(y[k]))
      throw InputError(fmt::format("{}: point {} ({}, {}) is not finite", what, k, x[k], y[k]));
    mx += x[k];
    my += y[k];
  }
  const double dn = static_cast<double>(n);
  mx /= dn;
  my /= dn;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    sxx += (x[k] - mx) * (x[k] - mx);
    sxy += (x[k] - mx) * (y[k] - my);
    syy += (y[k] - my) * (y[k] - my);
  }
  if (!(sxx > 0.0))
    throw InputError(fmt::format("{}: all {} x values are equal ({}), the slope is undefined", what, n, mx));
  LinearFit fit;
  fit.points = n;
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  double ss_res = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = y[k] - (fit.slope * x[k] + fit.intercept);
    ss_res += r * r;
  }
  fit.r_squared = syy > 0.0 ? 1.0 - ss_res / syy : (ss_res > 0.0 ? 0.0 : 1.0);
  if (n > 2) {
    const double s2 = ss_res / (dn - 2.0);
    fit.slope_stderr = std::sqrt(s2 / sxx);
    fit.intercept_stderr = std::sqrt(s2 * (1.0 / dn + mx * mx / sxx));
  }
  return fit;
}

TimeSeries restrict_time(const TimeSeries& series, double t_begin_s, double t_end_s) {
  TimeSeries out;
  for (std::size_t k = 0; k < series.time.size() && k < series.value.size(); ++k) {
    if (series.time[k] >= t_begin_s && series.time[k] <= t_end_s) {
      out.time.push_back(series.time[k]);
      out.value.push_back(series.value[k]);
    }
  }
  return out;
}

LinearFit fit_line(const TimeSeries& series, double t_begin_s, double t_end_s, const std::string& what) {
  series.validate(what);
  if (!(t_begin_s <= t_end_s))
    throw InputError(fmt::format("{}: fit interval [{}, {}] s is empty", what, t_begin_s, t_end_s));
  const TimeSeries part = restrict_time(series, t_begin_s, t_end_s);
  if (part.size() < 2)
    throw InputError(
        fmt::format("{}: only {} samples in the fit interval [{}, {}] s (series spans "
                    "[{}, {}] s); a line needs at least 2",
                    what, part.size(), t_begin_s, t_end_s, series.time.front(), series.time.back()));
  return fit_line(part.time, part.value, what);
}

LinearFit fit_line(const TimeSeries& series, const std::string& what) {
  series.validate(what, 2);
  return fit_line(series.time, series.value, what);
}

TimeSeries cut_before_boundary(const TimeSeries& series, double boundary, double margin) {
  if (!(std::isfinite(margin) && margin >= 0.0))
    throw InputError(fmt::format("cut_before_boundary: margin = {} must be finite and >= 0", margin));
  if (!std::isfinite(boundary))
    throw InputError(fmt::format("cut_before_boundary: boundary = {} must be finite", boundary));
  TimeSeries out;
  for (std::size_t k = 0; k < series.time.size() && k < series.value.size(); ++k) {
    if (std::abs(series.value[k] - boundary) <= margin) break;
    out.time.push_back(series.time[k]);
    out.value.push_back(series.value[k]);
  }
  return out;
}

double interpolate_crossing(double x0, double g0, double x1, double g1, double level) {
  if (g1 == g0) return x0;
  double w = (level - g0) / (g1 - g0);
  if (w < 0.0) w = 0.0;
  if (w > 1.0) w = 1.0;
  return x0 + w * (x1 - x0);
}

}  // namespace oobleck::analysis
