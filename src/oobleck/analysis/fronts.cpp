#include "oobleck/analysis/fronts.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "oobleck/analysis/line_search.hpp"
#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

FrontCriterion velocity_front(double v0_m_per_s, double fraction) {
  if (!(std::isfinite(v0_m_per_s) && v0_m_per_s != 0.0))
    throw InputError(fmt::format("velocity_front: v_0 = {} m/s must be finite and non-zero", v0_m_per_s));
  if (!std::isfinite(fraction)) throw InputError(fmt::format("velocity_front: fraction = {} must be finite", fraction));
  return FrontCriterion{v0_m_per_s, fraction};
}

FrontCriterion scalar_front(double f_threshold) {
  if (!std::isfinite(f_threshold))
    throw InputError(fmt::format("scalar_front: threshold = {} must be finite", f_threshold));
  return FrontCriterion{1.0, f_threshold};
}

namespace {

void check_criterion(const FrontCriterion& c, const char* what) {
  if (!(std::isfinite(c.scale) && c.scale != 0.0))
    throw InputError(
        fmt::format("{}: criterion scale = {} must be finite and non-zero (v_0 for u_z, "
                    "1 for f)",
                    what, c.scale));
  if (!std::isfinite(c.threshold))
    throw InputError(fmt::format("{}: criterion threshold = {} must be finite", what, c.threshold));
}

void check_geometry(const FrontGeometry& g, const GridField2D& field, const char* what) {
  if (g.direction != 1.0 && g.direction != -1.0)
    throw InputError(
        fmt::format("{}: direction = {} must be +1 or -1 (sign of the intruder's "
                    "motion along z)",
                    what, g.direction));
  const double tol = 1e-9 * field.h;
  if (!std::isfinite(g.intruder_radius_m) || g.intruder_radius_m < field.origin_x - tol ||
      g.intruder_radius_m > field.x_max() + tol)
    throw InputError(
        fmt::format("{}: intruder radius R = {} m lies outside the grid's r range "
                    "[{}, {}] m",
                    what, g.intruder_radius_m, field.origin_x, field.x_max()));
  if (!std::isfinite(g.axis_r_m) || g.axis_r_m < field.origin_x - tol || g.axis_r_m > field.x_max() + tol)
    throw InputError(fmt::format("{}: axis column r = {} m lies outside the grid's r range [{}, {}] m", what,
                                 g.axis_r_m, field.origin_x, field.x_max()));
  if (!std::isfinite(g.transverse_offset_m))
    throw InputError(fmt::format("{}: transverse offset = {} m must be finite", what, g.transverse_offset_m));
  if (!(std::isfinite(g.tip_gap_m) && g.tip_gap_m >= 0.0) || !(std::isfinite(g.edge_gap_m) && g.edge_gap_m >= 0.0))
    throw InputError(
        fmt::format("{}: tip gap = {} m and edge gap = {} m must be finite and >= 0", what, g.tip_gap_m, g.edge_gap_m));
}

bool same_grid(const GridField2D& a, const GridField2D& b) {
  return a.nx == b.nx && a.ny == b.ny && a.h == b.h && a.origin_x == b.origin_x && a.origin_y == b.origin_y;
}

}  // namespace

FrontPosition measure_front(const GridField2D& field, double tip_z_m, const FrontCriterion& criterion,
                            const FrontGeometry& geometry) {
  field.validate("measure_front: field");
  check_criterion(criterion, "measure_front");
  check_geometry(geometry, field, "measure_front");
  const double d = geometry.direction;
  const double inv_scale = 1.0 / criterion.scale;

  FrontPosition out;
  out.tip_z_m = tip_z_m;

  // Longitudinal: the axis column, search coordinate s = d (z - z_tip).
  {
    const std::vector<double> column = field.column_at(geometry.axis_r_m, "measure_front: axis column");
    const double s0 = geometry.tip_gap_m;
    const double g_tip =
        sample_line(column, field.origin_y, field.h, tip_z_m + d * s0, "measure_front: tip z (+ gap)") * inv_scale;
    std::vector<double> s, g;
    const double eps = 1e-9 * field.h;
    for (std::size_t n = 0; n < field.ny; ++n) {
      const std::size_t j = d > 0 ? n : field.ny - 1 - n;
      const double sj = d * (field.y(j) - tip_z_m);
      if (sj > s0 + eps) {
        s.push_back(sj);
        g.push_back(column[j] * inv_scale);
      }
    }
    const LineCrossing c = search_front(s0, g_tip, s, g, criterion.threshold, geometry.search);
    out.longitudinal_found = c.found;
    out.longitudinal_at_boundary = c.at_end;
    out.longitudinal_ahead_m = c.found ? c.position : 0.0;
    out.longitudinal_z_m = tip_z_m + d * out.longitudinal_ahead_m;
  }

  // Transverse: the row at the tip depth, search coordinate s = r - R.
  {
    const double z_line = tip_z_m + d * geometry.transverse_offset_m;
    const std::vector<double> row = field.row_at(z_line, "measure_front: transverse line at the tip depth");
    const double radius = geometry.intruder_radius_m;
    const double s0 = geometry.edge_gap_m;
    const double g_edge =
        sample_line(row, field.origin_x, field.h, radius + s0, "measure_front: edge r (+ gap)") * inv_scale;
    std::vector<double> s, g;
    const double eps = 1e-9 * field.h;
    for (std::size_t i = 0; i < field.nx; ++i) {
      const double si = field.x(i) - radius;
      if (si > s0 + eps) {
        s.push_back(si);
        g.push_back(row[i] * inv_scale);
      }
    }
    const LineCrossing c = search_front(s0, g_edge, s, g, criterion.threshold, geometry.search);
    out.transverse_found = c.found;
    out.transverse_at_boundary = c.at_end;
    out.transverse_from_edge_m = c.found ? c.position : 0.0;
    out.transverse_r_m = radius + out.transverse_from_edge_m;
  }
  return out;
}

std::vector<IntrusionFrame> time_filter(const std::vector<IntrusionFrame>& frames, std::size_t window_frames) {
  if (frames.empty()) throw InputError("time_filter: no frames");
  if (window_frames == 0 || window_frames % 2 == 0)
    throw InputError(
        fmt::format("time_filter: window = {} frames must be odd and >= 1 (centered "
                    "moving average; 1 = no filtering)",
                    window_frames));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k].field.validate(fmt::format("time_filter: frame {} field", k));
    if (!std::isfinite(frames[k].time_s) || !std::isfinite(frames[k].tip_z_m))
      throw InputError(fmt::format("time_filter: frame {} has a non-finite time ({}) or tip z ({})", k,
                                   frames[k].time_s, frames[k].tip_z_m));
    if (k > 0 && !(frames[k].time_s > frames[k - 1].time_s))
      throw InputError(
          fmt::format("time_filter: frame times must be strictly increasing, but t[{}] = {} "
                      "s <= t[{}] = {} s",
                      k, frames[k].time_s, k - 1, frames[k - 1].time_s));
    if (!same_grid(frames[k].field, frames[0].field))
      throw InputError(
          fmt::format("time_filter: frame {} is on a different grid than frame 0 ({} x {} "
                      "nodes, h = {} m vs {} x {}, h = {} m)",
                      k, frames[k].field.nx, frames[k].field.ny, frames[k].field.h, frames[0].field.nx,
                      frames[0].field.ny, frames[0].field.h));
  }
  if (window_frames == 1) return frames;
  const std::size_t half = window_frames / 2;
  std::vector<IntrusionFrame> out = frames;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::size_t lo = k >= half ? k - half : 0;
    const std::size_t hi = std::min(frames.size() - 1, k + half);
    std::vector<double>& v = out[k].field.values;
    std::fill(v.begin(), v.end(), 0.0);
    for (std::size_t m = lo; m <= hi; ++m)
      for (std::size_t n = 0; n < v.size(); ++n) v[n] += frames[m].field.values[n];
    const double inv = 1.0 / static_cast<double>(hi - lo + 1);
    for (double& x : v) x *= inv;
  }
  return out;
}

namespace {
TimeSeries collect(const FrontSeries& s, bool longitudinal, double (*value)(const FrontSeries&, const FrontPosition&)) {
  TimeSeries out;
  for (const FrontPosition& p : s.frames) {
    if (longitudinal ? !p.longitudinal_found : !p.transverse_found) continue;
    out.time.push_back(p.time_s);
    out.value.push_back(value(s, p));
  }
  return out;
}
}  // namespace

TimeSeries FrontSeries::longitudinal_depth() const {
  return collect(*this, true, [](const FrontSeries& s, const FrontPosition& p) {
    return s.direction * (p.longitudinal_z_m - s.reference_z_m);
  });
}
TimeSeries FrontSeries::longitudinal_ahead() const {
  return collect(*this, true, [](const FrontSeries&, const FrontPosition& p) { return p.longitudinal_ahead_m; });
}
TimeSeries FrontSeries::transverse_radius() const {
  return collect(*this, false, [](const FrontSeries&, const FrontPosition& p) { return p.transverse_r_m; });
}
TimeSeries FrontSeries::transverse_from_edge() const {
  return collect(*this, false, [](const FrontSeries&, const FrontPosition& p) { return p.transverse_from_edge_m; });
}

FrontSeries measure_front_series(const std::vector<IntrusionFrame>& frames, const FrontCriterion& criterion,
                                 const FrontGeometry& geometry, std::size_t window_frames, double reference_z_m) {
  if (frames.empty()) throw InputError("measure_front_series: no frames");
  const std::vector<IntrusionFrame> filtered = time_filter(frames, window_frames);
  FrontSeries out;
  out.direction = geometry.direction;
  out.intruder_radius_m = geometry.intruder_radius_m;
  out.reference_z_m = std::isnan(reference_z_m) ? frames.front().tip_z_m : reference_z_m;
  if (!std::isfinite(out.reference_z_m))
    throw InputError(fmt::format("measure_front_series: reference z = {} m must be finite", reference_z_m));
  const GridField2D& grid = frames.front().field;
  out.longitudinal_wall_z_m = geometry.direction < 0 ? grid.origin_y : grid.y_max();
  out.transverse_wall_r_m = grid.x_max();
  out.frames.reserve(filtered.size());
  for (const IntrusionFrame& f : filtered) {
    FrontPosition p = measure_front(f.field, f.tip_z_m, criterion, geometry);
    p.time_s = f.time_s;
    out.frames.push_back(p);
  }
  return out;
}

FrontSpeeds front_factors(const LinearFit& longitudinal_depth_fit, const LinearFit& transverse_fit, double v0_m_per_s) {
  if (!(std::isfinite(v0_m_per_s) && v0_m_per_s != 0.0))
    throw InputError(fmt::format("front_factors: v_0 = {} m/s must be finite and non-zero", v0_m_per_s));
  FrontSpeeds s;
  s.longitudinal = longitudinal_depth_fit;
  s.transverse = transverse_fit;
  const double v0 = std::abs(v0_m_per_s);
  s.v0_m_per_s = v0;
  s.v_fl_m_per_s = longitudinal_depth_fit.slope;
  s.v_fl_stderr_m_per_s = longitudinal_depth_fit.slope_stderr;
  s.v_ft_m_per_s = transverse_fit.slope;
  s.v_ft_stderr_m_per_s = transverse_fit.slope_stderr;
  s.k_l = s.v_fl_m_per_s / v0 - 1.0;
  s.k_l_stderr = s.v_fl_stderr_m_per_s / v0;
  s.k_t = s.v_ft_m_per_s / v0;
  s.k_t_stderr = s.v_ft_stderr_m_per_s / v0;
  if (s.k_t != 0.0) {
    s.ratio = s.k_l / s.k_t;
    const double a = s.k_l_stderr / s.k_t;
    const double b = s.k_l * s.k_t_stderr / (s.k_t * s.k_t);
    s.ratio_stderr = std::sqrt(a * a + b * b);
  } else {
    s.ratio = std::numeric_limits<double>::quiet_NaN();
    s.ratio_stderr = std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

namespace {
// The frames of one front entering its fit: found, inside [t_begin, t_end], and before the first
// frame (inside the window) whose front reached the grid's end or came within margin of the wall.
TimeSeries fit_points(const FrontSeries& series, bool longitudinal, const FrontFitOptions& o, std::string& why) {
  TimeSeries out;
  std::size_t found = 0, in_window = 0;
  double cut_time = std::numeric_limits<double>::quiet_NaN();
  for (const FrontPosition& p : series.frames) {
    const bool ok = longitudinal ? p.longitudinal_found : p.transverse_found;
    if (!ok) continue;
    ++found;
    if (p.time_s < o.t_begin_s || p.time_s > o.t_end_s) continue;
    ++in_window;
    const bool at_end = longitudinal ? p.longitudinal_at_boundary : p.transverse_at_boundary;
    const double gap = longitudinal ? std::abs(p.longitudinal_z_m - series.longitudinal_wall_z_m)
                                    : std::abs(p.transverse_r_m - series.transverse_wall_r_m);
    if (at_end || gap <= o.wall_margin_m) {
      cut_time = p.time_s;
      break;
    }
    out.time.push_back(p.time_s);
    out.value.push_back(longitudinal ? series.direction * (p.longitudinal_z_m - series.reference_z_m)
                                     : p.transverse_r_m);
  }
  why = fmt::format("{} frames, front found in {}, {} inside [{}, {}] s{}", series.frames.size(), found, in_window,
                    o.t_begin_s, o.t_end_s,
                    std::isnan(cut_time) ? std::string()
                                         : fmt::format(", cut at t = {} s where the front came within {} m "
                                                       "of the wall",
                                                       cut_time, o.wall_margin_m));
  return out;
}

/// The time of a front's farthest extent among the frames fit_points would take: the first frame
/// of the largest distance ahead of the tip (longitudinal) or of the largest radius (transverse);
/// +inf without frames.
double farthest_time(const FrontSeries& series, bool longitudinal, const FrontFitOptions& o) {
  std::string why;
  const TimeSeries pts = fit_points(series, longitudinal, o, why);
  double best = -std::numeric_limits<double>::infinity(), t = std::numeric_limits<double>::infinity();
  std::size_t k = 0;
  for (const FrontPosition& p : series.frames) {
    if (k == pts.size()) break;
    if (p.time_s != pts.time[k]) continue;  // (a frame fit_points left out)
    ++k;
    const double extent = longitudinal ? p.longitudinal_ahead_m : p.transverse_r_m;
    if (extent > best) {
      best = extent;
      t = p.time_s;
    }
  }
  return t;
}
}  // namespace

FrontSpeeds front_speeds(const FrontSeries& series, double v0_m_per_s, const FrontFitOptions& options_in) {
  if (series.frames.empty()) throw InputError("front_speeds: empty front series");
  FrontFitOptions options = options_in;
  if (options.to_farthest) {
    // Both fronts over the common advancing window: until the first of them is at its farthest.
    options.to_farthest = false;
    options.t_end_s =
        std::min({options.t_end_s, farthest_time(series, true, options), farthest_time(series, false, options)});
    if (!(options.t_begin_s <= options.t_end_s)) options.t_end_s = options.t_begin_s;
  }
  if (!(std::isfinite(options.wall_margin_m) && options.wall_margin_m >= 0.0))
    throw InputError(fmt::format("front_speeds: wall margin = {} m must be finite and >= 0", options.wall_margin_m));
  if (!(options.t_begin_s <= options.t_end_s))
    throw InputError(fmt::format("front_speeds: fit interval [{}, {}] s is empty", options.t_begin_s, options.t_end_s));
  const std::size_t min_points = std::max<std::size_t>(2, options.min_points);
  std::string why_l, why_t;
  const TimeSeries l = fit_points(series, true, options, why_l);
  const TimeSeries t = fit_points(series, false, options, why_t);
  if (l.size() < min_points)
    throw InputError(
        fmt::format("front_speeds: only {} points for the longitudinal front fit (at least "
                    "{} needed): {}",
                    l.size(), min_points, why_l));
  if (t.size() < min_points)
    throw InputError(
        fmt::format("front_speeds: only {} points for the transverse front fit (at least {} "
                    "needed): {}",
                    t.size(), min_points, why_t));
  l.validate("front_speeds: longitudinal front series", min_points);
  t.validate("front_speeds: transverse front series", min_points);
  FrontSpeeds s = front_factors(fit_line(l.time, l.value, "front_speeds: longitudinal fit"),
                                fit_line(t.time, t.value, "front_speeds: transverse fit"), v0_m_per_s);
  s.longitudinal_t_begin_s = l.time.front();
  s.longitudinal_t_end_s = l.time.back();
  s.transverse_t_begin_s = t.time.front();
  s.transverse_t_end_s = t.time.back();
  return s;
}

}  // namespace oobleck::analysis
