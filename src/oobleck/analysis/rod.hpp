#pragma once
// S2 (rod impact, paper Figs. 7-8, scenes.md S2): rod velocity and acceleration from its sampled
// position by finite differences (the paper's Fig. 8 caption: "first-order finite difference
// scheme; the length of the stencil is chosen to remove the effects of elastic waves"), the
// acceleration from the contact force, the peak deceleration, the impact time, and the
// displacement |dz| vs depth directly below the rod (Fig. 7c). See docs/analysis.md "Rod impact".
//
// Sign convention: z is the grid's axial coordinate (z up in the scenes); `direction` is the sign
// of the rod's motion along z before impact (-1: launched downward on a z-up grid).
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "oobleck/analysis/data.hpp"

namespace oobleck::analysis {

/// Where a finite difference over [t_k, t_{k+L}] is placed in time.
enum class DifferenceTime {
  forward,   ///< at t_k: first-order accurate there (error ~ y'' (t_{k+L} - t_k) / 2)
  backward,  ///< at t_{k+L}: first-order accurate there
  midpoint,  ///< at (t_k + t_{k+L}) / 2: second-order accurate there
};

/// Finite difference over a stencil of `stencil` sample intervals:
/// d_k = (y[k+L] - y[k]) / (t[k+L] - t[k]), k = 0 ... N-1-L, placed at the time `at` says.
/// Non-uniform sampling is allowed. Throws InputError if stencil == 0, the series is invalid or
/// has fewer than stencil + 1 samples.
TimeSeries finite_difference(const TimeSeries& y, std::size_t stencil, DifferenceTime at = DifferenceTime::forward);

/// Rod position, velocity and acceleration.
struct RodKinematics {
  TimeSeries position;      ///< z of the rod [m] (as given)
  TimeSeries velocity;      ///< dz/dt [m/s]
  TimeSeries acceleration;  ///< d2z/dt2 [m/s^2]
};

/// velocity = finite_difference(position, stencil, at); acceleration = finite_difference(velocity,
/// stencil, at). Needs at least 2 * stencil + 1 samples.
RodKinematics rod_kinematics(const TimeSeries& position_m, std::size_t stencil,
                             DifferenceTime at = DifferenceTime::forward);

/// Acceleration from the contact force: a_z = F_z / m - g, with F_z [N] the z-component of the
/// force the mixture exerts on the rod and gravity g [m/s^2] acting along -z (pass 0 for F/m
/// alone). Throws InputError if mass <= 0 or g is not finite.
TimeSeries acceleration_from_force(const TimeSeries& force_N, double mass_kg, double gravity_m_per_s2 = 9.81);

/// The largest deceleration, deceleration(t) = -direction * a_z(t) (positive when the rod is
/// being slowed), and when it occurs (first sample of the maximum).
struct PeakDeceleration {
  double deceleration_m_per_s2 = 0.0;
  double time_s = 0.0;
  std::size_t index = 0;
};
PeakDeceleration peak_deceleration(const TimeSeries& acceleration_m_per_s2, double direction = -1.0);

/// First contact from the force: the first time |F| exceeds threshold_N, linearly interpolated
/// between the last sample at or below and the first above (the first sample's time if it is
/// already above). nullopt if it never does. threshold_N must be >= 0.
std::optional<double> impact_time_from_force(const TimeSeries& force_N, double threshold_N = 0.0);

/// First contact from the position of the rod's tip: the first time direction * (z_tip -
/// z_surface) >= 0, linearly interpolated between samples. nullopt if it never reaches it.
std::optional<double> impact_time_from_position(const TimeSeries& tip_z_m, double surface_z_m, double direction = -1.0);

/// |dz| vs depth directly below the rod (Fig. 7c).
struct DepthProfile {
  std::vector<double> depth_m;         ///< direction * (z - z_surface): depth below the surface [m]
  std::vector<double> displacement_m;  ///< |u_z| at that depth [m]
  LinearFit fit;                       ///< displacement vs depth (r_squared = linearity)
};

/// Sample the z-displacement field `uz_m` (nodal, on the (r, z) grid) on the column r = axis_r_m
/// from z_start_m (the rod's tip at that time; interpolated there) through every node beyond it
/// in `direction`, up to z_end_m (NaN: the grid's end), and fit |u_z| vs depth linearly.
DepthProfile displacement_below_rod(const GridField2D& uz_m, double z_start_m, double z_surface_m,
                                    double direction = -1.0, double axis_r_m = 0.0,
                                    double z_end_m = std::numeric_limits<double>::quiet_NaN());

}  // namespace oobleck::analysis
