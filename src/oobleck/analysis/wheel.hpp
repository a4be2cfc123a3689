#pragma once
// S4 (running on oobleck, paper Figs. 11-12, scenes.md S4): hub height and distance travelled
// across a periodic track, the "stays at the surface" / "sinks" verdicts, and the free-surface
// height profile from a nodal volume-fraction field. See docs/analysis.md "Wheel".
#include <cstddef>
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
  double duration_s = 0.0;                ///< t_last - t_first
  double hub_height_initial_m = 0.0;
  double hub_height_final_m = 0.0;
  double hub_height_min_m = 0.0;
  double hub_height_min_time_s = 0.0;
  double height_loss_m = 0.0;             ///< initial - final
  double distance_m = 0.0;                ///< forward * (x_unwrapped_last - x_unwrapped_first)
  double mean_forward_speed_m_per_s = 0.0;  ///< distance / duration
  bool stays_at_surface = false;  ///< height_loss < wheel radius and distance > 0
  bool sinks = false;             ///< final hub height below the initial bed surface
  bool ever_below_surface = false;  ///< minimum hub height below the initial bed surface
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

}  // namespace oobleck::analysis
