#include "oobleck/analysis/wheel.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

std::vector<double> unwrap_periodic(const std::vector<double>& x_m, double period_m) {
  if (!(std::isfinite(period_m) && period_m > 0.0))
    throw InputError(fmt::format("unwrap_periodic: period = {} m must be finite and > 0", period_m));
  std::vector<double> out(x_m.size());
  double shift = 0.0;
  for (std::size_t k = 0; k < x_m.size(); ++k) {
    if (!std::isfinite(x_m[k])) throw InputError(fmt::format("unwrap_periodic: x[{}] = {} is not finite", k, x_m[k]));
    if (k > 0) {
      const double step = x_m[k] - x_m[k - 1];
      shift -= period_m * std::round(step / period_m);
    }
    out[k] = x_m[k] + shift;
  }
  return out;
}

WheelSummary summarize_wheel(const HubTrack& hub, const WheelCriteria& c) {
  if (hub.time_s.size() != hub.x_m.size() || hub.time_s.size() != hub.y_m.size())
    throw InputError(fmt::format("summarize_wheel: {} times, {} x and {} y values (sizes must match)",
                                 hub.time_s.size(), hub.x_m.size(), hub.y_m.size()));
  TimeSeries ty{hub.time_s, hub.y_m};
  ty.validate("summarize_wheel: hub height", 2);
  TimeSeries tx{hub.time_s, hub.x_m};
  tx.validate("summarize_wheel: hub x", 2);
  if (!(std::isfinite(c.wheel_radius_m) && c.wheel_radius_m > 0.0))
    throw InputError(fmt::format("summarize_wheel: wheel radius = {} m must be finite and > 0", c.wheel_radius_m));
  if (!std::isfinite(c.bed_surface_m))
    throw InputError(fmt::format("summarize_wheel: bed surface = {} m must be finite", c.bed_surface_m));
  if (c.forward != 1.0 && c.forward != -1.0)
    throw InputError(fmt::format("summarize_wheel: forward = {} must be +1 or -1", c.forward));
  WheelSummary s;
  s.x_unwrapped_m = unwrap_periodic(hub.x_m, c.track_length_m);
  s.duration_s = hub.time_s.back() - hub.time_s.front();
  s.hub_height_initial_m = hub.y_m.front();
  s.hub_height_final_m = hub.y_m.back();
  s.hub_height_min_m = hub.y_m.front();
  s.hub_height_min_time_s = hub.time_s.front();
  for (std::size_t k = 1; k < hub.y_m.size(); ++k)
    if (hub.y_m[k] < s.hub_height_min_m) {
      s.hub_height_min_m = hub.y_m[k];
      s.hub_height_min_time_s = hub.time_s[k];
    }
  s.height_loss_m = s.hub_height_initial_m - s.hub_height_final_m;
  s.distance_m = c.forward * (s.x_unwrapped_m.back() - s.x_unwrapped_m.front());
  s.mean_forward_speed_m_per_s = s.distance_m / s.duration_s;
  s.runs_on_surface_lowest_hub_m = s.hub_height_initial_m - 0.5 * c.wheel_radius_m;
  s.runs_on_surface = s.hub_height_min_m >= s.runs_on_surface_lowest_hub_m && s.distance_m > 0.0;
  s.sinks = s.hub_height_final_m < c.bed_surface_m;
  s.ever_below_surface = s.hub_height_min_m < c.bed_surface_m;
  return s;
}

SurfaceProfile free_surface(const GridField2D& phi, double phi_threshold) {
  phi.validate("free_surface: phi field");
  if (!std::isfinite(phi_threshold))
    throw InputError(fmt::format("free_surface: threshold {} must be finite", phi_threshold));
  SurfaceProfile p;
  p.x_m.resize(phi.nx);
  p.height_m.assign(phi.nx, std::numeric_limits<double>::quiet_NaN());
  p.has_material.assign(phi.nx, false);
  for (std::size_t i = 0; i < phi.nx; ++i) {
    p.x_m[i] = phi.x(i);
    for (std::size_t n = 0; n < phi.ny; ++n) {
      const std::size_t j = phi.ny - 1 - n;
      if (phi.at(i, j) >= phi_threshold) {
        p.has_material[i] = true;
        p.height_m[i] = (j + 1 == phi.ny) ? phi.y(j)
                                          : interpolate_crossing(phi.y(j), phi.at(i, j), phi.y(j + 1), phi.at(i, j + 1),
                                                                 phi_threshold);
        break;
      }
    }
  }
  return p;
}

namespace {
/// rms values and their ratio from the sums of squared deviations and of squared values over r.points.
void finish_scatter(PressureScatter& r, double dev2, double p2) {
  if (r.points == 0) return;
  r.rms_deviation_Pa = std::sqrt(dev2 / static_cast<double>(r.points));
  r.rms_Pa = std::sqrt(p2 / static_cast<double>(r.points));
  r.relative = r.rms_Pa > 0.0 ? r.rms_deviation_Pa / r.rms_Pa : 0.0;
}
}  // namespace

PressureScatter pressure_scatter(std::span<const double> x_m, std::span<const double> y_m, std::span<const double> p_Pa,
                                 const ScatterWindow& w) {
  if (x_m.size() != y_m.size() || x_m.size() != p_Pa.size())
    throw InputError(fmt::format("pressure_scatter: {} x, {} y and {} pressure values differ in number", x_m.size(),
                                 y_m.size(), p_Pa.size()));
  if (!(w.cell_m > 0.0) || !std::isfinite(w.cell_m))
    throw InputError(fmt::format("pressure_scatter: cell size {} must be positive", w.cell_m));
  auto inside = [&](std::size_t k) {
    double dx = x_m[k] - w.x_centre_m;
    if (w.period_m > 0.0) dx -= w.period_m * std::round(dx / w.period_m);
    return std::abs(dx) <= w.half_width_m && y_m[k] >= w.y_min_m && y_m[k] <= w.y_max_m && std::isfinite(p_Pa[k]);
  };
  auto cell = [&](std::size_t k) {
    return std::pair<long, long>(static_cast<long>(std::floor((x_m[k] - w.origin_x_m) / w.cell_m)),
                                 static_cast<long>(std::floor((y_m[k] - w.origin_y_m) / w.cell_m)));
  };
  struct Acc {
    double sum = 0.0;
    std::int64_t n = 0;
  };
  std::map<std::pair<long, long>, Acc> cells;  // ordered: the sums below do not depend on hashing
  for (std::size_t k = 0; k < x_m.size(); ++k) {
    if (!inside(k)) continue;
    Acc& a = cells[cell(k)];
    a.sum += p_Pa[k];
    ++a.n;
  }
  PressureScatter r;
  double dev2 = 0.0, p2 = 0.0;
  for (std::size_t k = 0; k < x_m.size(); ++k) {
    if (!inside(k)) continue;
    const Acc& a = cells[cell(k)];
    if (a.n < 2) continue;
    const double d = p_Pa[k] - a.sum / static_cast<double>(a.n);
    dev2 += d * d;
    p2 += p_Pa[k] * p_Pa[k];
    ++r.points;
  }
  for (const auto& [key, a] : cells) r.cells += a.n >= 2 ? 1 : 0;
  finish_scatter(r, dev2, p2);  // points = 0: no cell in the window holds two points
  return r;
}

PressureScatter pool(std::span<const PressureScatter> samples) {
  PressureScatter r;
  double dev2 = 0.0, p2 = 0.0;
  for (const auto& s : samples) {
    if (s.points <= 0) continue;
    const auto n = static_cast<double>(s.points);
    dev2 += n * s.rms_deviation_Pa * s.rms_deviation_Pa;
    p2 += n * s.rms_Pa * s.rms_Pa;
    r.points += s.points;
    r.cells += s.cells;
  }
  finish_scatter(r, dev2, p2);
  return r;
}

}  // namespace oobleck::analysis
