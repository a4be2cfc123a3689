#include "oobleck/analysis/annular.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "oobleck/analysis/line_search.hpp"
#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

namespace {

void check_geometry(const AnnularGeometry& g, const char* what) {
  if (!(std::isfinite(g.bob_radius_m) && g.bob_radius_m > 0.0))
    throw InputError(fmt::format("{}: bob radius r_0 = {} m must be finite and > 0", what, g.bob_radius_m));
  if (!(std::isfinite(g.outer_radius_m) && g.outer_radius_m > g.bob_radius_m))
    throw InputError(fmt::format("{}: outer radius r_o = {} m must be finite and > r_0 = {} m", what, g.outer_radius_m,
                                 g.bob_radius_m));
  if (!(std::isfinite(g.bob_speed_m_per_s) && g.bob_speed_m_per_s != 0.0))
    throw InputError(fmt::format("{}: bob speed u_i = {} m/s must be finite and non-zero", what, g.bob_speed_m_per_s));
  if (!std::isfinite(g.sample_z_m) || !std::isfinite(g.start_time_s))
    throw InputError(
        fmt::format("{}: sample z = {} m and start time = {} s must be finite", what, g.sample_z_m, g.start_time_s));
}

void check_frame_fits(const GridField2D& f, const AnnularGeometry& g, const std::string& what) {
  f.validate(what);
  const double tol = 1e-9 * f.h;
  if (g.bob_radius_m < f.origin_x - tol || g.outer_radius_m > f.x_max() + tol)
    throw InputError(fmt::format("{}: gap [{}, {}] m does not lie inside the grid's r range [{}, {}] m", what,
                                 g.bob_radius_m, g.outer_radius_m, f.origin_x, f.x_max()));
}

void check_frames(const std::vector<ShearFrame>& frames, const AnnularGeometry& g, const char* what) {
  if (frames.empty()) throw InputError(fmt::format("{}: no frames", what));
  check_geometry(g, what);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    check_frame_fits(frames[k].v_theta, g, fmt::format("{}: frame {}", what, k));
    const GridField2D& a = frames[k].v_theta;
    const GridField2D& b = frames[0].v_theta;
    if (a.nx != b.nx || a.ny != b.ny || a.h != b.h || a.origin_x != b.origin_x || a.origin_y != b.origin_y)
      throw InputError(fmt::format("{}: frame {} is on a different grid than frame 0", what, k));
    if (!std::isfinite(frames[k].time_s))
      throw InputError(fmt::format("{}: frame {} time {} is not finite", what, k, frames[k].time_s));
    if (k > 0 && !(frames[k].time_s > frames[k - 1].time_s))
      throw InputError(fmt::format("{}: frame times must be strictly increasing, but t[{}] = {} s <= t[{}] = {} s",
                                   what, k, frames[k].time_s, k - 1, frames[k - 1].time_s));
  }
}

// Node indices with r_0 <= r <= r_o (1e-9 h tolerance).
std::vector<std::size_t> gap_nodes(const GridField2D& f, const AnnularGeometry& g, bool strict) {
  std::vector<std::size_t> idx;
  const double eps = 1e-9 * f.h;
  for (std::size_t i = 0; i < f.nx; ++i) {
    const double r = f.x(i);
    const bool inside = strict ? (r > g.bob_radius_m + eps && r < g.outer_radius_m - eps)
                               : (r >= g.bob_radius_m - eps && r <= g.outer_radius_m + eps);
    if (inside) idx.push_back(i);
  }
  return idx;
}

}  // namespace

std::vector<ShearProfile> surface_profiles(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                           const std::vector<double>& angles_rad) {
  check_frames(frames, geometry, "surface_profiles");
  const GridField2D& grid = frames.front().v_theta;
  const std::vector<std::size_t> nodes = gap_nodes(grid, geometry, false);
  std::vector<ShearProfile> out;
  for (const double theta : angles_rad) {
    if (!std::isfinite(theta)) throw InputError(fmt::format("surface_profiles: angle {} rad is not finite", theta));
    const double t = geometry.start_time_s + theta * geometry.bob_radius_m / std::abs(geometry.bob_speed_m_per_s);
    const double tol = 1e-9 * std::max(1.0, std::abs(t));
    if (t < frames.front().time_s - tol || t > frames.back().time_s + tol)
      throw InputError(
          fmt::format("surface_profiles: angle {} rad is reached at t = {} s, outside the frames' "
                      "time range [{}, {}] s",
                      theta, t, frames.front().time_s, frames.back().time_s));
    std::size_t k = 0;
    while (k + 2 < frames.size() && frames[k + 1].time_s < t) ++k;
    double w = 0.0;
    if (frames.size() > 1) {
      w = (t - frames[k].time_s) / (frames[k + 1].time_s - frames[k].time_s);
      w = std::clamp(w, 0.0, 1.0);
    }
    const std::vector<double> a = frames[k].v_theta.row_at(geometry.sample_z_m, "surface_profiles: sample z");
    const std::vector<double> b =
        frames.size() > 1 ? frames[k + 1].v_theta.row_at(geometry.sample_z_m, "surface_profiles: sample z") : a;
    ShearProfile p;
    p.angle_rad = theta;
    p.time_s = t;
    for (const std::size_t i : nodes) {
      p.r_m.push_back(grid.x(i));
      p.v_over_ui.push_back(((1.0 - w) * a[i] + w * b[i]) / geometry.bob_speed_m_per_s);
    }
    out.push_back(std::move(p));
  }
  return out;
}

NewtonianAnnulus newtonian_annulus(double inner_radius_m, double inner_speed_m_per_s, double outer_radius_m) {
  if (!(std::isfinite(inner_radius_m) && inner_radius_m > 0.0 && std::isfinite(outer_radius_m) &&
        outer_radius_m > inner_radius_m))
    throw InputError(fmt::format("newtonian_annulus: radii r_i = {} m, r_o = {} m must satisfy 0 < r_i < r_o",
                                 inner_radius_m, outer_radius_m));
  if (!std::isfinite(inner_speed_m_per_s))
    throw InputError(fmt::format("newtonian_annulus: inner speed {} m/s must be finite", inner_speed_m_per_s));
  const double denom = outer_radius_m * outer_radius_m - inner_radius_m * inner_radius_m;
  NewtonianAnnulus n;
  n.A_per_s = -inner_speed_m_per_s * inner_radius_m / denom;
  n.B_m2_per_s = inner_speed_m_per_s * inner_radius_m * outer_radius_m * outer_radius_m / denom;
  return n;
}

double newtonian_distance(const std::vector<double>& r_m, const std::vector<double>& v_over_ui, double inner_radius_m,
                          double outer_radius_m) {
  if (r_m.size() != v_over_ui.size())
    throw InputError(fmt::format("newtonian_distance: {} radii but {} values", r_m.size(), v_over_ui.size()));
  if (r_m.size() < 2) throw InputError("newtonian_distance: a profile needs at least 2 points");
  for (std::size_t k = 0; k < r_m.size(); ++k) {
    if (!std::isfinite(r_m[k]) || !std::isfinite(v_over_ui[k]))
      throw InputError(fmt::format("newtonian_distance: point {} ({}, {}) is not finite", k, r_m[k], v_over_ui[k]));
    if (k > 0 && !(r_m[k] > r_m[k - 1]))
      throw InputError(fmt::format("newtonian_distance: radii must be strictly increasing (r[{}] = {} m)", k, r_m[k]));
  }
  const NewtonianAnnulus n = newtonian_annulus(inner_radius_m, 1.0, outer_radius_m);
  double integral = 0.0;
  for (std::size_t k = 1; k < r_m.size(); ++k) {
    const double e0 = v_over_ui[k - 1] - n.v_theta(r_m[k - 1]);
    const double e1 = v_over_ui[k] - n.v_theta(r_m[k]);
    integral += 0.5 * (e0 * e0 + e1 * e1) * (r_m[k] - r_m[k - 1]);
  }
  return std::sqrt(integral / (r_m.back() - r_m.front()));
}

double newtonian_distance(const ShearProfile& profile, const AnnularGeometry& geometry) {
  check_geometry(geometry, "newtonian_distance");
  return newtonian_distance(profile.r_m, profile.v_over_ui, geometry.bob_radius_m, geometry.outer_radius_m);
}

namespace {

/// Walking outward from the bob along z = sample_z_m, the first radius where value(node value, r)
/// drops below `threshold` (linear interpolation between nodes; at the bob the value is
/// interpolated at r_0). `what` names the caller in errors.
template <class Value>
ShearFront outward_front(double time_s, const GridField2D& field, const AnnularGeometry& geometry, double threshold,
                         const std::string& what, Value&& value) {
  check_geometry(geometry, what.c_str());
  check_frame_fits(field, geometry, what + ": field");
  if (!std::isfinite(threshold)) throw InputError(fmt::format("{}: threshold {} must be finite", what, threshold));
  const std::vector<double> row = field.row_at(geometry.sample_z_m, what + ": sample z");
  const double g0 = value(sample_line(row, field.origin_x, field.h, geometry.bob_radius_m, what + ": bob radius"),
                          geometry.bob_radius_m);
  std::vector<double> s, g;
  for (const std::size_t i : gap_nodes(field, geometry, false)) {
    const double r = field.x(i);
    if (r - geometry.bob_radius_m > 1e-9 * field.h) {
      s.push_back(r - geometry.bob_radius_m);
      g.push_back(value(row[i], r));
    }
  }
  const LineCrossing c = search_front(0.0, g0, s, g, threshold, FrontSearch::contiguous);
  ShearFront out;
  out.time_s = time_s;
  out.found = c.found;
  out.radius_m = geometry.bob_radius_m + c.position;
  out.at_wall = c.at_end;  // the value stays above the threshold up to the last node of the gap
  return out;
}

template <class Front>
std::vector<ShearFront> front_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                     const char* what, Front&& front_of) {
  check_frames(frames, geometry, what);
  std::vector<ShearFront> out;
  out.reserve(frames.size());
  for (const ShearFrame& f : frames) out.push_back(front_of(f));
  return out;
}

}  // namespace

ShearFront jammed_front(const ShearFrame& frame, const AnnularGeometry& geometry, double threshold) {
  const double omega = geometry.bob_speed_m_per_s / geometry.bob_radius_m;
  return outward_front(frame.time_s, frame.v_theta, geometry, threshold, "jammed_front",
                       [&](double v, double r) { return v / (omega * r); });
}

ShearFront structure_front(const ShearFrame& frame, const AnnularGeometry& geometry, double f_threshold) {
  if (frame.f.values.empty()) throw InputError("structure_front: the frame holds no structure field f");
  return outward_front(frame.time_s, frame.f, geometry, f_threshold, "structure_front",
                       [](double f, double) { return f; });
}

std::vector<ShearFront> jammed_front_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                            double threshold) {
  return front_series(frames, geometry, "jammed_front_series",
                      [&](const ShearFrame& f) { return jammed_front(f, geometry, threshold); });
}

std::vector<ShearFront> structure_front_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                               double f_threshold) {
  return front_series(frames, geometry, "structure_front_series",
                      [&](const ShearFrame& f) { return structure_front(f, geometry, f_threshold); });
}

std::optional<double> front_at_wall_time(const std::vector<ShearFront>& fronts, const AnnularGeometry& geometry,
                                         double wall_margin_m) {
  if (!(std::isfinite(wall_margin_m) && wall_margin_m >= 0.0))
    throw InputError(fmt::format("front_at_wall_time: wall margin = {} m must be finite and >= 0", wall_margin_m));
  for (const ShearFront& f : fronts)
    if (f.found && (f.at_wall || geometry.outer_radius_m - f.radius_m <= wall_margin_m)) return f.time_s;
  return std::nullopt;
}

TimeSeries front_radius_series(const std::vector<ShearFront>& fronts) {
  TimeSeries s;
  for (const ShearFront& f : fronts)
    if (f.found) {
      s.time.push_back(f.time_s);
      s.value.push_back(f.radius_m);
    }
  return s;
}

LinearFit front_speed(const std::vector<ShearFront>& fronts, const AnnularGeometry& geometry,
                      const FrontFitOptions& options) {
  check_geometry(geometry, "front_speed");
  if (fronts.empty()) throw InputError("front_speed: no fronts");
  if (!(std::isfinite(options.wall_margin_m) && options.wall_margin_m >= 0.0))
    throw InputError(fmt::format("front_speed: wall margin = {} m must be finite and >= 0", options.wall_margin_m));
  TimeSeries s;
  std::size_t found = 0;
  double cut = std::numeric_limits<double>::quiet_NaN();
  for (const ShearFront& f : fronts) {
    if (!f.found) continue;
    ++found;
    if (f.time_s < options.t_begin_s || f.time_s > options.t_end_s) continue;
    if (f.at_wall || geometry.outer_radius_m - f.radius_m <= options.wall_margin_m) {
      cut = f.time_s;
      break;
    }
    s.time.push_back(f.time_s);
    s.value.push_back(f.radius_m);
  }
  const std::size_t min_points = std::max<std::size_t>(2, options.min_points);
  if (s.size() < min_points)
    throw InputError(
        fmt::format("front_speed: only {} points to fit (at least {} needed): {} frames, front found "
                    "in {}, window [{}, {}] s{}",
                    s.size(), min_points, fronts.size(), found, options.t_begin_s, options.t_end_s,
                    std::isnan(cut) ? std::string() : fmt::format(", cut at the outer wall at t = {} s", cut)));
  s.validate("front_speed: front radius series", min_points);
  return fit_line(s.time, s.value, "front_speed");
}

FlowStop flow_stop_time(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                        double speed_tolerance_m_per_s, double wall_margin_m, double threshold) {
  check_frames(frames, geometry, "flow_stop_time");
  if (!(std::isfinite(speed_tolerance_m_per_s) && speed_tolerance_m_per_s >= 0.0))
    throw InputError(
        fmt::format("flow_stop_time: speed tolerance = {} m/s must be finite and >= 0", speed_tolerance_m_per_s));
  if (!(std::isfinite(wall_margin_m) && wall_margin_m >= 0.0))
    throw InputError(fmt::format("flow_stop_time: wall margin = {} m must be finite and >= 0", wall_margin_m));
  const std::vector<std::size_t> inner = gap_nodes(frames.front().v_theta, geometry, true);
  FlowStop out;
  for (const ShearFrame& fr : frames) {
    double vmax = 0.0;
    for (std::size_t j = 0; j < fr.v_theta.ny; ++j)
      for (const std::size_t i : inner) vmax = std::max(vmax, std::abs(fr.v_theta.at(i, j)));
    const bool by_velocity = !inner.empty() && vmax < speed_tolerance_m_per_s;
    const ShearFront front = jammed_front(fr, geometry, threshold);
    const bool by_front = front.found && (front.at_wall || geometry.outer_radius_m - front.radius_m <= wall_margin_m);
    if (by_velocity || by_front) {
      out.time_s = fr.time_s;
      out.by_velocity = by_velocity;
      out.by_front = by_front;
      return out;
    }
  }
  return out;
}

TimeSeries outer_rotation_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry) {
  check_frames(frames, geometry, "outer_rotation_series");
  const GridField2D& grid = frames.front().v_theta;
  const double eps = 1e-9 * grid.h;
  const double r_mid = 0.5 * (geometry.bob_radius_m + geometry.outer_radius_m);
  std::vector<std::size_t> nodes;
  for (std::size_t i = 0; i < grid.nx; ++i) {
    const double r = grid.x(i);
    if (r >= r_mid - eps && r < geometry.outer_radius_m - eps) nodes.push_back(i);
  }
  if (nodes.empty())
    throw InputError(fmt::format("outer_rotation_series: no node in the outer half [{}, {}) m of the gap", r_mid,
                                 geometry.outer_radius_m));
  const double omega_bob = geometry.bob_speed_m_per_s / geometry.bob_radius_m;
  TimeSeries out;
  for (const ShearFrame& fr : frames) {
    const std::vector<double> row = fr.v_theta.row_at(geometry.sample_z_m, "outer_rotation_series: sample z");
    double sum = 0.0;
    for (const std::size_t i : nodes) sum += row[i] / (omega_bob * grid.x(i));
    out.time.push_back(fr.time_s);
    out.value.push_back(sum / static_cast<double>(nodes.size()));
  }
  return out;
}

OuterArrest outer_arrest(const TimeSeries& outer_rotation, double fraction) {
  outer_rotation.validate("outer_arrest: outer rotation series");
  if (!(std::isfinite(fraction) && fraction > 0.0 && fraction < 1.0))
    throw InputError(fmt::format("outer_arrest: fraction = {} must lie in (0, 1)", fraction));
  OuterArrest a;
  a.fraction = fraction;
  const auto& v = outer_rotation.value;
  const std::size_t k_peak = static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
  a.peak = v[k_peak];
  a.peak_time_s = outer_rotation.time[k_peak];
  a.final_value = v.back();
  if (a.peak > 0.0) {
    for (std::size_t k = k_peak + 1; k < v.size(); ++k) {
      if (v[k] < fraction * a.peak) {
        a.arrest_time_s = outer_rotation.time[k];
        break;
      }
    }
  }
  return a;
}

namespace {
/// ln(r_o/r_0) of the gap; throws InputError (naming `who`) unless 0 < r_0 < r_o.
double log_radius_ratio(const AnnularGeometry& geometry, const char* who) {
  const double r0 = geometry.bob_radius_m, ro = geometry.outer_radius_m;
  if (!(r0 > 0.0 && ro > r0))
    throw InputError(fmt::format("{}: radii r_0 = {}, r_o = {} [m]: need 0 < r_0 < r_o", who, r0, ro));
  return std::log(ro / r0);
}
}  // namespace

double steady_bob_speed_limit(double max_shear_rate_1_s, const AnnularGeometry& geometry) {
  if (!(std::isfinite(max_shear_rate_1_s) && max_shear_rate_1_s > 0.0))
    throw InputError(fmt::format("steady_bob_speed_limit: shear rate = {} must be positive [1/s]", max_shear_rate_1_s));
  return max_shear_rate_1_s * geometry.bob_radius_m * log_radius_ratio(geometry, "steady_bob_speed_limit");
}

CouetteLimit steady_couette_limit(const std::vector<double>& tau_Pa, const std::vector<double>& gamma_dot_1_s,
                                  const AnnularGeometry& geometry) {
  const std::size_t n = tau_Pa.size();
  if (n < 2 || gamma_dot_1_s.size() != n)
    throw InputError(fmt::format("steady_couette_limit: {} stresses and {} shear rates: need >= 2 of each, as many", n,
                                 gamma_dot_1_s.size()));
  const double r0 = geometry.bob_radius_m, ro = geometry.outer_radius_m;
  const double span = 2.0 * log_radius_ratio(geometry, "steady_couette_limit");  // ln tau_0 - ln tau_wall
  std::vector<double> u(n);                                                      // ln tau
  for (std::size_t k = 0; k < n; ++k) {
    if (!(std::isfinite(tau_Pa[k]) && tau_Pa[k] > 0.0 && (k == 0 || tau_Pa[k] > tau_Pa[k - 1])))
      throw InputError(
          fmt::format("steady_couette_limit: stress sample {} = {} Pa: stresses must be positive and "
                      "strictly increasing",
                      k, tau_Pa[k]));
    if (!(std::isfinite(gamma_dot_1_s[k]) && gamma_dot_1_s[k] >= 0.0))
      throw InputError(fmt::format("steady_couette_limit: shear rate sample {} = {} 1/s must be finite and >= 0", k,
                                   gamma_dot_1_s[k]));
    u[k] = std::log(tau_Pa[k]);
  }
  // G(u) = (1/2) integral of gamma_dot du from u_0: exact for gamma_dot linear in u on each interval.
  std::vector<double> G(n, 0.0);
  for (std::size_t k = 1; k < n; ++k)
    G[k] = G[k - 1] + 0.25 * (gamma_dot_1_s[k] + gamma_dot_1_s[k - 1]) * (u[k] - u[k - 1]);
  auto G_at = [&](double x) {  // u_0 <= x <= u_{n-1}
    const auto it = std::upper_bound(u.begin(), u.end(), x);
    const std::size_t j =
        std::min<std::size_t>(static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - u.begin(), 1)) - 1, n - 2);
    const double h = u[j + 1] - u[j], s = x - u[j];
    const double g0 = gamma_dot_1_s[j], g1 = gamma_dot_1_s[j + 1];
    return G[j] + 0.5 * (g0 * s + 0.5 * (g1 - g0) * s * s / h);
  };
  CouetteLimit best;
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (u[k] - span < u[0]) continue;
    const double omega = G[k] - G_at(u[k] - span);
    if (!any || omega * r0 > best.bob_speed_m_per_s) {
      best.bob_speed_m_per_s = omega * r0;
      best.bob_stress_Pa = tau_Pa[k];
      best.at_end = k == n - 1;
      any = true;
    }
  }
  if (!any)
    throw InputError(
        fmt::format("steady_couette_limit: the samples span a factor {:.3g} in stress, less than the "
                    "gap's (r_o/r_0)^2 = {:.3g}",
                    tau_Pa.back() / tau_Pa.front(), (ro / r0) * (ro / r0)));
  return best;
}

}  // namespace oobleck::analysis
