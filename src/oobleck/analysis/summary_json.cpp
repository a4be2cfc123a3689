#include "oobleck/analysis/summary_json.hpp"

#include <cmath>

namespace oobleck::analysis {

namespace {
nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
nlohmann::json nums(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(num(x));
  return a;
}
}  // namespace

nlohmann::json to_json(const LinearFit& fit) {
  return {{"slope", num(fit.slope)},
          {"intercept", num(fit.intercept)},
          {"r_squared", num(fit.r_squared)},
          {"slope_stderr", num(fit.slope_stderr)},
          {"intercept_stderr", num(fit.intercept_stderr)},
          {"points", fit.points}};
}

nlohmann::json to_json(const TimeSeries& series) {
  return {{"time", nums(series.time)}, {"value", nums(series.value)}};
}

nlohmann::json to_json(const FrontSpeeds& s) {
  nlohmann::json l = to_json(s.longitudinal);
  l["t_begin"] = num(s.longitudinal_t_begin_s);
  l["t_end"] = num(s.longitudinal_t_end_s);
  nlohmann::json t = to_json(s.transverse);
  t["t_begin"] = num(s.transverse_t_begin_s);
  t["t_end"] = num(s.transverse_t_end_s);
  return {{"v0", num(s.v0_m_per_s)},
          {"v_fl", num(s.v_fl_m_per_s)},
          {"v_fl_stderr", num(s.v_fl_stderr_m_per_s)},
          {"v_ft", num(s.v_ft_m_per_s)},
          {"v_ft_stderr", num(s.v_ft_stderr_m_per_s)},
          {"k_l", num(s.k_l)},
          {"k_l_stderr", num(s.k_l_stderr)},
          {"k_t", num(s.k_t)},
          {"k_t_stderr", num(s.k_t_stderr)},
          {"k_l_over_k_t", num(s.ratio)},
          {"k_l_over_k_t_stderr", num(s.ratio_stderr)},
          {"longitudinal_fit", l},
          {"transverse_fit", t}};
}

nlohmann::json to_json(const FrontSeries& series) {
  nlohmann::json frames = nlohmann::json::array();
  for (const FrontPosition& p : series.frames)
    frames.push_back({{"time", num(p.time_s)},
                      {"tip_z", num(p.tip_z_m)},
                      {"longitudinal",
                       {{"found", p.longitudinal_found},
                        {"at_boundary", p.longitudinal_at_boundary},
                        {"z", num(p.longitudinal_z_m)},
                        {"ahead", num(p.longitudinal_ahead_m)}}},
                      {"transverse",
                       {{"found", p.transverse_found},
                        {"at_boundary", p.transverse_at_boundary},
                        {"r", num(p.transverse_r_m)},
                        {"from_edge", num(p.transverse_from_edge_m)}}}});
  return {{"reference_z", num(series.reference_z_m)},
          {"direction", num(series.direction)},
          {"intruder_radius", num(series.intruder_radius_m)},
          {"frames", frames}};
}

nlohmann::json to_json(const PeakDeceleration& p) {
  return {{"peak_deceleration", num(p.deceleration_m_per_s2)}, {"peak_deceleration_time", num(p.time_s)}};
}

nlohmann::json to_json(const DepthProfile& p) {
  return {{"depth", nums(p.depth_m)}, {"displacement", nums(p.displacement_m)}, {"fit", to_json(p.fit)}};
}

nlohmann::json to_json(const std::vector<ShearProfile>& profiles) {
  nlohmann::json a = nlohmann::json::array();
  for (const ShearProfile& p : profiles)
    a.push_back(
        {{"angle", num(p.angle_rad)}, {"time", num(p.time_s)}, {"r", nums(p.r_m)}, {"v_over_ui", nums(p.v_over_ui)}});
  return a;
}

nlohmann::json to_json(const FlowStop& stop) {
  return {{"time", stop.time_s ? num(*stop.time_s) : nlohmann::json(nullptr)},
          {"by_velocity", stop.by_velocity},
          {"by_front", stop.by_front}};
}

nlohmann::json to_json(const OuterArrest& a) {
  return {{"peak", num(a.peak)},
          {"peak_time", num(a.peak_time_s)},
          {"final", num(a.final_value)},
          {"fraction", num(a.fraction)},
          {"time", a.arrest_time_s ? num(*a.arrest_time_s) : nlohmann::json(nullptr)}};
}

nlohmann::json to_json(const WheelSummary& s, const WheelCriteria& c) {
  return {{"hub_height_initial", num(s.hub_height_initial_m)},
          {"hub_height_final", num(s.hub_height_final_m)},
          {"hub_height_min", num(s.hub_height_min_m)},
          {"hub_height_min_time", num(s.hub_height_min_time_s)},
          {"height_loss", num(s.height_loss_m)},
          {"bed_surface", num(c.bed_surface_m)},
          {"wheel_radius", num(c.wheel_radius_m)},
          {"distance", num(s.distance_m)},
          {"duration", num(s.duration_s)},
          {"mean_forward_speed", num(s.mean_forward_speed_m_per_s)},
          {"runs_on_surface", s.runs_on_surface},
          {"runs_on_surface_lowest_hub", num(s.runs_on_surface_lowest_hub_m)},
          {"sinks", s.sinks},
          {"ever_below_surface", s.ever_below_surface}};
}

}  // namespace oobleck::analysis
