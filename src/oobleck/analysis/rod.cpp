#include "oobleck/analysis/rod.hpp"

#include <cmath>

#include <fmt/format.h>

#include "oobleck/analysis/line_search.hpp"
#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

namespace {
void check_direction(double direction, const char* what) {
  if (direction != 1.0 && direction != -1.0)
    throw InputError(
        fmt::format("{}: direction = {} must be +1 or -1 (sign of the rod's motion along z)", what, direction));
}
}  // namespace

TimeSeries finite_difference(const TimeSeries& y, std::size_t stencil, DifferenceTime at) {
  if (stencil == 0) throw InputError("finite_difference: stencil must span at least 1 sample interval");
  y.validate("finite_difference", stencil + 1);
  TimeSeries d;
  const std::size_t n = y.size() - stencil;
  d.time.resize(n);
  d.value.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t0 = y.time[k], t1 = y.time[k + stencil];
    d.value[k] = (y.value[k + stencil] - y.value[k]) / (t1 - t0);
    switch (at) {
      case DifferenceTime::forward: d.time[k] = t0; break;
      case DifferenceTime::backward: d.time[k] = t1; break;
      case DifferenceTime::midpoint: d.time[k] = 0.5 * (t0 + t1); break;
    }
  }
  return d;
}

RodKinematics rod_kinematics(const TimeSeries& position_m, std::size_t stencil, DifferenceTime at) {
  if (stencil == 0) throw InputError("rod_kinematics: stencil must span at least 1 sample interval");
  position_m.validate("rod_kinematics: position", 2 * stencil + 1);
  RodKinematics k;
  k.position = position_m;
  k.velocity = finite_difference(position_m, stencil, at);
  k.acceleration = finite_difference(k.velocity, stencil, at);
  return k;
}

TimeSeries acceleration_from_force(const TimeSeries& force_N, double mass_kg, double gravity_m_per_s2) {
  force_N.validate("acceleration_from_force: force");
  if (!(std::isfinite(mass_kg) && mass_kg > 0.0))
    throw InputError(fmt::format("acceleration_from_force: rod mass = {} kg must be finite and > 0", mass_kg));
  if (!std::isfinite(gravity_m_per_s2))
    throw InputError(fmt::format("acceleration_from_force: gravity = {} m/s^2 must be finite", gravity_m_per_s2));
  TimeSeries a = force_N;
  for (double& v : a.value) v = v / mass_kg - gravity_m_per_s2;
  return a;
}

PeakDeceleration peak_deceleration(const TimeSeries& acceleration_m_per_s2, double direction) {
  acceleration_m_per_s2.validate("peak_deceleration: acceleration");
  check_direction(direction, "peak_deceleration");
  PeakDeceleration p;
  p.deceleration_m_per_s2 = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < acceleration_m_per_s2.size(); ++k) {
    const double dec = -direction * acceleration_m_per_s2.value[k];
    if (dec > p.deceleration_m_per_s2) {
      p.deceleration_m_per_s2 = dec;
      p.time_s = acceleration_m_per_s2.time[k];
      p.index = k;
    }
  }
  return p;
}

std::optional<double> impact_time_from_force(const TimeSeries& force_N, double threshold_N) {
  force_N.validate("impact_time_from_force: force");
  if (!(std::isfinite(threshold_N) && threshold_N >= 0.0))
    throw InputError(fmt::format("impact_time_from_force: threshold = {} N must be finite and >= 0", threshold_N));
  for (std::size_t k = 0; k < force_N.size(); ++k) {
    const double f = std::abs(force_N.value[k]);
    if (f > threshold_N) {
      if (k == 0) return force_N.time[0];
      const double fp = std::abs(force_N.value[k - 1]);
      return interpolate_crossing(force_N.time[k - 1], fp, force_N.time[k], f, threshold_N);
    }
  }
  return std::nullopt;
}

std::optional<double> impact_time_from_position(const TimeSeries& tip_z_m, double surface_z_m, double direction) {
  tip_z_m.validate("impact_time_from_position: tip position");
  check_direction(direction, "impact_time_from_position");
  if (!std::isfinite(surface_z_m))
    throw InputError(fmt::format("impact_time_from_position: surface z = {} m must be finite", surface_z_m));
  for (std::size_t k = 0; k < tip_z_m.size(); ++k) {
    const double s = direction * (tip_z_m.value[k] - surface_z_m);
    if (s >= 0.0) {
      if (k == 0) return tip_z_m.time[0];
      const double sp = direction * (tip_z_m.value[k - 1] - surface_z_m);
      return interpolate_crossing(tip_z_m.time[k - 1], sp, tip_z_m.time[k], s, 0.0);
    }
  }
  return std::nullopt;
}

DepthProfile displacement_below_rod(const GridField2D& uz_m, double z_start_m, double z_surface_m, double direction,
                                    double axis_r_m, double z_end_m) {
  uz_m.validate("displacement_below_rod: displacement field");
  check_direction(direction, "displacement_below_rod");
  if (!std::isfinite(z_surface_m))
    throw InputError(fmt::format("displacement_below_rod: surface z = {} m must be finite", z_surface_m));
  const double end = std::isnan(z_end_m) ? (direction < 0 ? uz_m.origin_y : uz_m.y_max()) : z_end_m;
  if (!std::isfinite(end) || !(direction * (end - z_start_m) > 0.0))
    throw InputError(
        fmt::format("displacement_below_rod: end z = {} m must lie beyond the start z = {} m "
                    "in the direction of motion ({})",
                    end, z_start_m, direction));
  const std::vector<double> column = uz_m.column_at(axis_r_m, "displacement_below_rod: axis column");
  DepthProfile p;
  p.depth_m.push_back(direction * (z_start_m - z_surface_m));
  p.displacement_m.push_back(
      std::abs(sample_line(column, uz_m.origin_y, uz_m.h, z_start_m, "displacement_below_rod: start z")));
  const double eps = 1e-9 * uz_m.h;
  for (std::size_t n = 0; n < uz_m.ny; ++n) {
    const std::size_t j = direction > 0 ? n : uz_m.ny - 1 - n;
    const double z = uz_m.y(j);
    if (direction * (z - z_start_m) > eps && direction * (end - z) >= -eps) {
      p.depth_m.push_back(direction * (z - z_surface_m));
      p.displacement_m.push_back(std::abs(column[j]));
    }
  }
  if (p.depth_m.size() < 2)
    throw InputError(
        fmt::format("displacement_below_rod: fewer than 2 samples between z = {} m and z = {} m", z_start_m, end));
  p.fit = fit_line(p.depth_m, p.displacement_m, "displacement_below_rod: |dz| vs depth fit");
  return p;
}

}  // namespace oobleck::analysis
