#pragma once
// S1 (annular shear, paper Fig. 6, scenes.md S1): surface v_theta(r)/u_i profiles at given bob
// rotation angles, the steady Newtonian annular profile A r + B/r and a profile's distance from
// it, the jammed-front radius vs time, its speed, and the time when the flow stops.
// See docs/analysis.md "Annular shear".
//
// The v_theta field [m/s] lives on the axisymmetric (r, z) grid; the gap spans r_0 <= r <= r_o
// (bob radius r_0, fixed outer wall r_o), usually the grid's r range (grid offset to r_0).
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "oobleck/analysis/data.hpp"
#include "oobleck/analysis/fronts.hpp"

namespace oobleck::analysis {

/// One output frame of an annular-shear run.
struct ShearFrame {
  double time_s = 0.0;
  GridField2D v_theta;  ///< azimuthal velocity [m/s] on the (r, z) grid
  GridField2D f;        ///< micro-structure f of the grains on the same grid (empty: not sampled)
};

struct AnnularGeometry {
  double bob_radius_m = 0.0125;      ///< r_0, the rotating inner cylinder
  double outer_radius_m = 0.0485;    ///< r_o, the fixed outer wall
  double bob_speed_m_per_s = 0.084;  ///< u_i, the bob's surface speed (omega_bob = u_i / r_0)
  double sample_z_m = 0.0;           ///< height of the profile line (just below the free surface)
  double start_time_s = 0.0;         ///< time the bob starts rotating (theta = 0)
};

/// A radial profile of v_theta / u_i.
struct ShearProfile {
  double angle_rad = 0.0;  ///< bob rotation theta = u_i (t - t_start) / r_0
  double time_s = 0.0;
  std::vector<double> r_m;        ///< node radii r_0 <= r <= r_o
  std::vector<double> v_over_ui;  ///< v_theta(r) / u_i
};

/// Profile of v_theta/u_i along the line z = sample_z_m at nodes with r_0 <= r <= r_o, at the
/// times t = t_start + theta r_0 / u_i of the given angles, linearly interpolated in time between
/// the two bracketing frames (and in z between rows). Throws InputError when an angle's time lies
/// outside the frames, frames are on different grids or not time-ordered, or the geometry does
/// not fit the grid.
std::vector<ShearProfile> surface_profiles(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                           const std::vector<double>& angles_rad);

/// Steady Newtonian flow between a cylinder of radius r_i moving at surface speed u_i and a
/// fixed cylinder of radius r_o: v_theta = A r + B / r with A = -u_i r_i / (r_o^2 - r_i^2) [1/s],
/// B = u_i r_i r_o^2 / (r_o^2 - r_i^2) [m^2/s].
struct NewtonianAnnulus {
  double A_per_s = 0.0;
  double B_m2_per_s = 0.0;
  double v_theta(double r_m) const { return A_per_s * r_m + B_m2_per_s / r_m; }
};
NewtonianAnnulus newtonian_annulus(double inner_radius_m, double inner_speed_m_per_s, double outer_radius_m);

/// Normalised L2 distance of a profile v/u_i from the Newtonian one over its radial extent:
/// sqrt( integral (v/u_i - v_N/u_i)^2 dr / (r_last - r_first) ), trapezoidal rule over the
/// profile's points (dimensionless; 0 for an exact A r + B/r profile).
double newtonian_distance(const std::vector<double>& r_m, const std::vector<double>& v_over_ui, double inner_radius_m,
                          double outer_radius_m);
double newtonian_distance(const ShearProfile& profile, const AnnularGeometry& geometry);

/// Jammed-front radius in one frame: walking outward from the bob along z = sample_z_m, the
/// first radius where v_theta / (omega_bob r) drops below `threshold` (default 0.5), linearly
/// interpolated between nodes (at the bob the ratio is interpolated at r_0).
struct ShearFront {
  double time_s = 0.0;
  bool found = false;     ///< ratio >= threshold at the bob
  bool at_wall = false;   ///< ratio >= threshold up to the outer wall: front placed there
  double radius_m = 0.0;  ///< front radius (r_0 when not found)
};
ShearFront jammed_front(const ShearFrame& frame, const AnnularGeometry& geometry, double threshold = 0.5);

/// Structure front in one frame: walking outward from the bob along z = sample_z_m, the first
/// radius where the structure f drops below `f_threshold`, linearly interpolated between nodes
/// (the same search as jammed_front on f instead of the rotation ratio). Where the velocity front
/// says where the band co-rotates, this one says how far the jammed structure (E24) has spread.
/// Throws InputError when the frame has no f field.
ShearFront structure_front(const ShearFrame& frame, const AnnularGeometry& geometry, double f_threshold);

/// structure_front in every frame.
std::vector<ShearFront> structure_front_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                               double f_threshold);

/// First time the front is within wall_margin_m of the outer wall (or reached it); nullopt if never.
std::optional<double> front_at_wall_time(const std::vector<ShearFront>& fronts, const AnnularGeometry& geometry,
                                         double wall_margin_m);

/// jammed_front in every frame.
std::vector<ShearFront> jammed_front_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                                            double threshold = 0.5);

/// Front radius [m] vs time [s] of the frames where the front was found.
TimeSeries front_radius_series(const std::vector<ShearFront>& fronts);

/// Front speed: straight-line fit of the front radius vs time over [t_begin, t_end] of
/// `options`, stopping at the first frame whose front reached the outer wall or came within
/// options.wall_margin_m of it. slope = front speed [m/s]. Throws InputError with fewer than
/// options.min_points points.
LinearFit front_speed(const std::vector<ShearFront>& fronts, const AnnularGeometry& geometry,
                      const FrontFitOptions& options = {});

/// When the flow stops: the first frame where (a) max |v_theta| over the nodes strictly inside
/// the gap (r_0 < r < r_o, all rows) is below speed_tolerance_m_per_s, or (b) the jammed front
/// is within wall_margin_m of the outer wall (or reached it).
struct FlowStop {
  std::optional<double> time_s;  ///< nullopt: the flow never stops in the frames given
  bool by_velocity = false;      ///< criterion (a) held at that time
  bool by_front = false;         ///< criterion (b) held at that time
};
FlowStop flow_stop_time(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry,
                        double speed_tolerance_m_per_s, double wall_margin_m = 0.0, double threshold = 0.5);

/// Rotation of the outer half of the gap relative to the bob: along z = sample_z_m, the mean of
/// v_theta / (omega_bob r) over the nodes with (r_0 + r_o)/2 <= r < r_o (the wall node excluded),
/// in every frame. 1 = co-rotating rigidly with the bob, 0 = at rest. Throws InputError when
/// the outer half holds no node.
TimeSeries outer_rotation_series(const std::vector<ShearFrame>& frames, const AnnularGeometry& geometry);

/// Arrest of the outer half (S1: "all flow stops when the band reaches the outer wall"; with the
/// bob's speed prescribed the layer at the bob keeps shearing): the peak of the outer rotation
/// and its time, and the first later time at which it has fallen below `fraction` of that peak
/// (nullopt when it never does or the peak is <= 0). Whether it stays arrested: `final_value`.
struct OuterArrest {
  double peak = 0.0;  ///< max of the outer rotation [-]
  double peak_time_s = 0.0;
  double final_value = 0.0;  ///< outer rotation in the last frame [-]
  double fraction = 0.1;     ///< the criterion used
  std::optional<double> arrest_time_s;
};
OuterArrest outer_arrest(const TimeSeries& outer_rotation, double fraction = 0.1);

/// An upper bound [m/s] on the bob speed of any steady flow when no material point can shear
/// steadily faster than `max_shear_rate_1_s` (rheology::fastest_steady_shear at the bed's phi):
/// in a steady annular flow v_theta = r omega(r), the shear rate is gamma_dot >= r |d omega/dr|,
/// so along any radial line omega_bob = integral of r |d omega/dr| / r dr <= max_shear_rate
/// ln(r_o/r_0), i.e. u_i <= max_shear_rate r_0 ln(r_o/r_0). A necessary condition only: torque
/// balance forbids the whole gap shearing at the maximum rate (steady_couette_limit is exact).
/// Throws InputError for a non-positive rate or r_o <= r_0.
double steady_bob_speed_limit(double max_shear_rate_1_s, const AnnularGeometry& geometry);

/// The fastest bob speed of a steady 1D annular (Couette) flow of a material with the local
/// steady flow curve gamma_dot(tau), given as samples with the stress strictly increasing (one
/// shear rate per stress, as on the model's flow curve swept in f): torque balance gives
/// tau(r) = tau_0 (r_0/r)^2, so omega_bob(tau_0) = (1/2) integral of gamma_dot(tau)/tau dtau from
/// tau_0 (r_0/r_o)^2 to tau_0 (gamma_dot linear in ln tau between samples). omega_bob is
/// continuous in tau_0, so every bob speed up to the maximum over the sampled tau_0 has a steady
/// flow and none above it. Candidates whose wall stress falls below the first sample are skipped.
/// `at_end`: the maximum is at the last sample (the curve's top decides; e.g. a DST asymptote
/// gamma_dot_inf gives omega_bob -> gamma_dot_inf ln(r_o/r_0) as tau_0 -> infinity).
struct CouetteLimit {
  double bob_speed_m_per_s = 0.0;  ///< max of u_i = omega_bob r_0 over the sampled bob stresses
  double bob_stress_Pa = 0.0;      ///< tau_0 at the maximum
  bool at_end = false;
};
/// Throws InputError for fewer than 2 samples, sizes that differ, stresses not positive and
/// strictly increasing, negative or non-finite rates, r_o <= r_0, or no sample spanning the gap.
CouetteLimit steady_couette_limit(const std::vector<double>& tau_Pa, const std::vector<double>& gamma_dot_1_s,
                                  const AnnularGeometry& geometry);

}  // namespace oobleck::analysis
