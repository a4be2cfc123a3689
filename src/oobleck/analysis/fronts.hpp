#pragma once
// S3 (controlled intrusion, paper Figs. 9-10, scenes.md S3): jamming-front positions below and
// beside a flat-ended cylindrical intruder on the axis of an axisymmetric (r, z) grid, their
// speeds from straight-line fits, and the propagation factors k_l, k_t of Han et al. 2016.
//
// Definitions (docs/analysis.md "Intrusion fronts")
// - A front is the boundary of the region where g = field / scale >= threshold. For the
//   velocity front, field = u_z [m/s], scale = v_0 (the intruder's velocity along z, with its
//   sign, so that u_z / v_0 = 1 in material co-moving with the intruder) and threshold = 0.5:
//   the paper's u_z = 0.5 v_0 contour. For the structure front, field = f, scale = 1, threshold
//   = f_threshold.
// - The intruder moves along z in the direction `direction` (+1 or -1; -1 for a z-up grid with
//   the intruder pushed down). Its tip is its flat end at z_tip(t).
// - Longitudinal front: on the axis column (r = axis_r), walking from the tip in the direction
//   of motion, the point where g first drops below the threshold (contiguous search; or the
//   deepest node with g >= threshold, `FrontSearch::farthest`), linearly interpolated between
//   nodes; the value at the tip is interpolated between the two rows bracketing z_tip (the
//   search may start a gap ahead of the tip / beyond the edge, FrontGeometry::tip_gap_m).
//   Reported as z_front [m], as `ahead` = direction * (z_front - z_tip) >= 0, the distance of the
//   front ahead of the tip [m], and as the lab-frame penetration `depth` = direction * (z_front -
//   z_ref) [m], z_ref = the tip's z in the first frame unless set. v_fl is the slope of depth
//   vs time (lab frame), so k_l = v_fl / v_0 - 1 is the front's speed relative to the tip in
//   units of v_0 (the paper's definition; for a tip moving at exactly v_0 it is also the slope
//   of `ahead` divided by v_0).
// - Transverse front: along r at the tip depth (z_tip + direction * transverse_offset, linear
//   interpolation between rows), walking outward from the intruder's edge r = R, the radius
//   where g first drops below the threshold (or the largest r with g >= threshold, `farthest`).
//   Reported as r_front [m] and as `from_edge` = r_front - R [m]; v_ft is the slope of either vs
//   time and k_t = v_ft / v_0.
// - A front that never drops below the threshold before the grid ends is placed at the last
//   node and flagged `at_boundary`; where g < threshold already at the tip (edge), or at the
//   gap's end, there is no front: `found` is false and the position is the tip (edge).
#include <cstddef>
#include <limits>
#include <vector>

#include "oobleck/analysis/data.hpp"

namespace oobleck::analysis {

/// Which threshold crossing marks the front along a search line.
enum class FrontSearch {
  contiguous,  ///< first drop below the threshold walking away from the tip/edge (default)
  farthest,    ///< the farthest node with g >= threshold, interpolated with the next node
};

/// What is thresholded: g = field / scale >= threshold.
struct FrontCriterion {
  double scale = 1.0;      ///< v_0 [m/s] (signed) for u_z; 1 for f
  double threshold = 0.5;  ///< 0.5 for u_z / v_0; f_threshold for f
};

/// The paper's velocity front: u_z / v_0 >= 0.5 (v0_m_per_s signed like u_z of the intruder).
FrontCriterion velocity_front(double v0_m_per_s, double fraction = 0.5);
/// A structure front: f >= f_threshold.
FrontCriterion scalar_front(double f_threshold);

/// Where the fronts are looked for.
struct FrontGeometry {
  double direction = -1.0;           ///< sign of the intruder's motion along z (+1 or -1)
  double intruder_radius_m = 0.005;  ///< R: the transverse search starts at r = R [m]
  double axis_r_m = 0.0;             ///< r of the longitudinal search column [m]
  double transverse_offset_m = 0.0;  ///< transverse line at z_tip + direction * offset [m]
  /// Start the longitudinal search this far ahead of the tip, z_tip + direction * tip_gap [m]
  /// (e.g. half a cell when nodes inside the intruder carry no material velocity); distances
  /// are still measured from the tip.
  double tip_gap_m = 0.0;
  /// Start the transverse search at r = R + edge_gap [m]; distances still from the edge R.
  double edge_gap_m = 0.0;
  FrontSearch search = FrontSearch::contiguous;
};

/// Front positions in one frame.
struct FrontPosition {
  double time_s = 0.0;
  double tip_z_m = 0.0;
  bool longitudinal_found = false;        ///< g >= threshold at the tip
  bool longitudinal_at_boundary = false;  ///< g >= threshold up to the grid's end
  double longitudinal_z_m = 0.0;          ///< z of the longitudinal front [m]
  double longitudinal_ahead_m = 0.0;      ///< direction * (z_front - z_tip) [m]
  bool transverse_found = false;          ///< g >= threshold at the edge r = R
  bool transverse_at_boundary = false;    ///< g >= threshold up to the grid's outer radius
  double transverse_r_m = 0.0;            ///< r of the transverse front [m]
  double transverse_from_edge_m = 0.0;    ///< r_front - R [m]
};

/// Front positions in `field` for an intruder tip at z = tip_z_m. Throws InputError for an
/// invalid field, scale 0, direction not +-1, tip outside the grid, or R / axis_r outside it.
FrontPosition measure_front(const GridField2D& field, double tip_z_m, const FrontCriterion& criterion,
                            const FrontGeometry& geometry);

/// One output frame of an intrusion run.
struct IntrusionFrame {
  double time_s = 0.0;
  double tip_z_m = 0.0;  ///< z of the intruder's flat end at time_s [m]
  GridField2D field;     ///< u_z [m/s] or f on the (r, z) grid
};

/// Centered moving average of the fields over `window_frames` frames (odd; 1 = no filtering):
/// frame k becomes the mean of frames k - w/2 ... k + w/2, truncated to the available frames at
/// both ends (so the first and last w/2 frames average fewer frames). Times and tip positions
/// are unchanged. Models the finite frame rate / exposure of the experiments' imaging. Throws
/// InputError for an even or zero window, non-increasing times or fields on different grids.
std::vector<IntrusionFrame> time_filter(const std::vector<IntrusionFrame>& frames, std::size_t window_frames);

/// Front positions through a run.
struct FrontSeries {
  std::vector<FrontPosition> frames;
  double reference_z_m = 0.0;          ///< z_ref of the lab-frame depth (first tip z by default)
  double direction = -1.0;             ///< copied from the geometry
  double intruder_radius_m = 0.0;      ///< copied from the geometry
  double longitudinal_wall_z_m = 0.0;  ///< grid end in the direction of motion [m]
  double transverse_wall_r_m = 0.0;    ///< outer radius of the grid [m]

  /// Lab-frame depth direction * (z_front - z_ref) [m] of the frames where the front was found.
  TimeSeries longitudinal_depth() const;
  /// Distance of the longitudinal front ahead of the tip [m] (found frames).
  TimeSeries longitudinal_ahead() const;
  /// Transverse front radius r_front [m] (found frames).
  TimeSeries transverse_radius() const;
  /// Transverse front distance from the intruder's edge, r_front - R [m] (found frames).
  TimeSeries transverse_from_edge() const;
};

/// Filter the frames over `window_frames` (see time_filter) and measure the fronts in each.
/// `reference_z_m` = NaN means the first frame's tip z. Frames must share one grid.
FrontSeries measure_front_series(const std::vector<IntrusionFrame>& frames, const FrontCriterion& criterion,
                                 const FrontGeometry& geometry, std::size_t window_frames = 1,
                                 double reference_z_m = std::numeric_limits<double>::quiet_NaN());

/// Which part of a front series enters the straight-line fits.
struct FrontFitOptions {
  double t_begin_s = -std::numeric_limits<double>::infinity();  ///< fit only t >= t_begin
  double t_end_s = std::numeric_limits<double>::infinity();     ///< fit only t <= t_end
  /// Stop each series at the first frame whose front is within this distance of its wall
  /// (longitudinal: the grid end or the bed bottom, transverse: the outer radius) [m]. With 0,
  /// frames whose front reached the grid's end are still excluded.
  double wall_margin_m = 0.0;
  std::size_t min_points = 3;  ///< fewer points in a fit -> InputError
  /// Fit both fronts only until the first of them reaches its farthest extent (the first frame of
  /// its largest distance ahead of the tip, or of its largest radius), the common advancing window
  /// of fronts that later fall back; fronts that keep advancing are fitted whole, as without it.
  bool to_farthest = false;
};

/// Front speeds and the paper's propagation factors.
struct FrontSpeeds {
  LinearFit longitudinal;                                           ///< lab-frame depth [m] vs t [s]: slope = v_fl
  LinearFit transverse;                                             ///< r_front [m] vs t [s]: slope = v_ft
  double longitudinal_t_begin_s = 0.0, longitudinal_t_end_s = 0.0;  ///< fitted interval
  double transverse_t_begin_s = 0.0, transverse_t_end_s = 0.0;      ///< fitted interval
  double v0_m_per_s = 0.0;                                          ///< |v_0|
  double v_fl_m_per_s = 0.0, v_fl_stderr_m_per_s = 0.0;
  double v_ft_m_per_s = 0.0, v_ft_stderr_m_per_s = 0.0;
  double k_l = 0.0, k_l_stderr = 0.0;      ///< v_fl / v_0 - 1
  double k_t = 0.0, k_t_stderr = 0.0;      ///< v_ft / v_0
  double ratio = 0.0, ratio_stderr = 0.0;  ///< k_l / k_t (NaN when k_t = 0)
};

/// k_l, k_t and k_l/k_t from the two fits (slopes in m/s) and |v_0|. The standard errors are
/// propagated to first order, treating the two fits as independent and v_0 as exact:
/// s(k_l) = s(v_fl)/v_0, s(k_t) = s(v_ft)/v_0, s(k_l/k_t)^2 = (s(k_l)/k_t)^2 + (k_l s(k_t)/k_t^2)^2.
FrontSpeeds front_factors(const LinearFit& longitudinal_depth_fit, const LinearFit& transverse_fit, double v0_m_per_s);

/// Fit the fronts of `series` (lab-frame depth and r_front vs time) over the interval and wall
/// cut of `options`, then front_factors. Throws InputError when a fit has fewer than
/// options.min_points points (naming the series and why points were dropped).
FrontSpeeds front_speeds(const FrontSeries& series, double v0_m_per_s, const FrontFitOptions& options = {});

}  // namespace oobleck::analysis
