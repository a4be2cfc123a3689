#pragma once
// JSON views of the analysis results, for a run's summary.json. Keys follow issue 5's names
// (v_fl, k_l, front_speed, hub_height_initial, distance, ...); SI units throughout (m, s, m/s,
// m/s^2), listed in docs/analysis.md. Non-finite numbers (e.g. k_l/k_t with k_t = 0) become null.
#include <vector>

#include <nlohmann/json.hpp>

#include "oobleck/analysis/annular.hpp"
#include "oobleck/analysis/fronts.hpp"
#include "oobleck/analysis/rod.hpp"
#include "oobleck/analysis/wheel.hpp"

namespace oobleck::analysis {

/// {slope, intercept, r_squared, slope_stderr, intercept_stderr, points}
nlohmann::json to_json(const LinearFit& fit);
/// {time: [s], value: [...]}
nlohmann::json to_json(const TimeSeries& series);
/// {v0, v_fl, v_fl_stderr, v_ft, v_ft_stderr, k_l, k_l_stderr, k_t, k_t_stderr, k_l_over_k_t,
///  k_l_over_k_t_stderr, longitudinal_fit: {..., t_begin, t_end}, transverse_fit: {...}}
nlohmann::json to_json(const FrontSpeeds& speeds);
/// {time, tip_z, longitudinal: {found, at_boundary, z, ahead}, transverse: {found, at_boundary, r, from_edge}} per
/// frame
nlohmann::json to_json(const FrontSeries& series);
/// {peak_deceleration [m/s^2], peak_deceleration_time [s]}
nlohmann::json to_json(const PeakDeceleration& peak);
/// {depth: [m], displacement: [m], fit}
nlohmann::json to_json(const DepthProfile& profile);
/// [{angle, time, r: [m], v_over_ui: [-]}, ...]
nlohmann::json to_json(const std::vector<ShearProfile>& profiles);
/// {time: [s] or null, by_velocity, by_front}
nlohmann::json to_json(const FlowStop& stop);
nlohmann::json to_json(const OuterArrest& arrest);
/// {hub_height_initial, hub_height_final, hub_height_min, hub_height_min_time, height_loss,
///  bed_surface, wheel_radius, distance, duration, mean_forward_speed, runs_on_surface,
///  runs_on_surface_lowest_hub, sinks, ever_below_surface}
nlohmann::json to_json(const WheelSummary& summary, const WheelCriteria& criteria);

}  // namespace oobleck::analysis
