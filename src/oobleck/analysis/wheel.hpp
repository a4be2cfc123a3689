#pragma once
// S4 (running on oobleck, paper Figs. 11-12, scenes.md S4): hub height and distance travelled
// across a periodic track, the "runs on the surface" / "sinks" verdicts, and the free-surface
// height profile from a nodal volume-fraction field, and the point-to-point scatter of the granular
// pressure under the wheel (the SI's ringing figure). See docs/analysis.md "Wheel".
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "oobleck/analysis/data.hpp"

namespace oobleck::analysis {

/// Hub centre positions in a plane-strain run: x along the periodic track, y up [m].
struct HubTrack {
  std::vector<double> time_s;
  std::vector<double> x_m;  ///< as output, i.e. wrapped into the periodic cell
  std::vector<double> y_m;  ///< hub height
};

/// Undo periodic wrapping: whenever consecutive samples differ by more than period/2, shift the
/// rest of the series by -+period. Valid when the true step between samples is < period/2.
/// Throws InputError for a non-positive period or non-finite values.
std::vector<double> unwrap_periodic(const std::vector<double>& x_m, double period_m);

struct WheelCriteria {
  double track_length_m = 2.0;   ///< period of the track in x
  double wheel_radius_m = 0.15;  ///< outer radius (hub centre to paddle tip)
  double bed_surface_m = 0.5;    ///< initial free-surface height of the bed
  double forward = 1.0;          ///< +1: forward is +x; -1: forward is -x
};

struct WheelSummary {
  double duration_s = 0.0;  ///< t_last - t_first
  double hub_height_initial_m = 0.0;
  double hub_height_final_m = 0.0;
  double hub_height_min_m = 0.0;
  double hub_height_min_time_s = 0.0;
  double height_loss_m = 0.0;               ///< initial - final
  double distance_m = 0.0;                  ///< forward * (x_unwrapped_last - x_unwrapped_first)
  double mean_forward_speed_m_per_s = 0.0;  ///< distance / duration
  /// The hub never more than half a wheel radius below its start (min ≥ initial − R/2: the
  /// paddles reach at most ~0.2 R below the surface when the tips carry the wheel, whose hub
  /// then rides between surface + R cos 45° and surface + R) and distance > 0.
  bool runs_on_surface = false;
  double runs_on_surface_lowest_hub_m = 0.0;  ///< initial − R/2, the criterion's lowest hub height
  bool sinks = false;                         ///< final hub height below the initial bed surface
  /// (The two are R/2 apart: the hub starts at the surface + R, its lowest paddle tip on the
  /// surface; a wheel may meet neither.)
  bool ever_below_surface = false;    ///< minimum hub height below the initial bed surface
  std::vector<double> x_unwrapped_m;  ///< unwrapped hub x for every sample
};

/// Summarise a hub track (>= 2 samples, strictly increasing times, equal sizes).
WheelSummary summarize_wheel(const HubTrack& hub, const WheelCriteria& criteria);

/// Free-surface height per grid column from nodal volume fraction phi: scanning each column from
/// the top, the first node with phi >= threshold and the node above it bracket the surface,
/// which is placed by linear interpolation of phi = threshold between them (at the top node if
/// the column is filled to the top). Columns without material get NaN and has_material = false.
struct SurfaceProfile {
  std::vector<double> x_m;
  std::vector<double> height_m;
  std::vector<bool> has_material;
};
SurfaceProfile free_surface(const GridField2D& phi, double phi_threshold = 0.1);

/// Where the pressure scatter is measured: points with |x − x_centre| <= half_width (the shortest
/// periodic distance when period_m > 0) and y_min <= y <= y_max, binned into the grid's cells of
/// size cell_m from (origin_x_m, origin_y_m).
struct ScatterWindow {
  double x_centre_m = 0.0, half_width_m = 0.0, y_min_m = 0.0, y_max_m = 0.0;
  double origin_x_m = 0.0, origin_y_m = 0.0, cell_m = 0.0;
  double period_m = 0.0;  ///< track length along x (0: not periodic)
};

/// Point-to-point scatter of a point field p (the granular pressure p~) within the grid cells:
/// rms_deviation = sqrt(mean over points of (p − p̄_cell)²), p̄_cell the mean of the points in the
/// same cell, rms = sqrt(mean of p²) over the same points, relative = rms_deviation / rms ∈ [0, 1]
/// (per cell Σ(p − p̄)² = Σp² − n p̄²). The deviation from the cell mean is the part of the field
/// that a one-value-per-cell projection does not carry: for a smooth field only its variation
/// across a cell (|∇p| h/4 for a linear field sampled 2 × 2 per cell), for point-to-point noise
/// that cancels within each cell its full amplitude (ε p0 on a background p0). The ringing
/// instability of MPM (paper SI) is such noise; a real jump inside a cell counts too, and
/// `relative` is measured against the field itself (p~ = 0 is stress-free, so it has no arbitrary
/// offset). Points alone in their cell are not counted; points = 0 when no cell in the window
/// holds two. Throws InputError for unequal sizes or a non-positive cell.
struct PressureScatter {
  double relative = 0.0;
  double rms_deviation_Pa = 0.0;
  double rms_Pa = 0.0;
  std::int64_t points = 0;  ///< counted points (in the window, sharing their cell with another)
  std::int64_t cells = 0;   ///< cells with two or more points in the window
};
PressureScatter pressure_scatter(std::span<const double> x_m, std::span<const double> y_m, std::span<const double> p_Pa,
                                 const ScatterWindow& window);

/// Several samples pooled: rms_deviation = sqrt(Σ n_k rms_deviation_k² / Σ n_k), rms likewise,
/// relative their ratio, points and cells summed (samples with no points are skipped).
PressureScatter pool(std::span<const PressureScatter> samples);

}  // namespace oobleck::analysis
