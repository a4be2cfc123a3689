// [analysis] kind = "intrusion" (S3, scenes.md; docs/analysis.md "Fronts"): the intruder's
// track and, at every sample, the nodal fields of the mixture's u_z and the grains' structure f
// (E24); in the summary the fronts of u_z = fraction v_0 and of f = f_threshold below
// (longitudinal) and beside (transverse) the intruder with their fitted speeds,
// k_l = v_fl/v_0 - 1 and k_t = v_ft/v_0.
#include <cmath>
#include <utility>

#include "oobleck/analysis/fronts.hpp"
#include "oobleck/analysis/summary_json.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/run/analysis_kinds.hpp"
#include "oobleck/run/body_track.hpp"
#include "oobleck/run/field_frames.hpp"
#include "oobleck/run/run_output.hpp"

namespace oobleck::run {

namespace {

template <class G>
class IntrusionAnalysis final : public SceneAnalysis<G> {
  static constexpr int D = G::dim;
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  IntrusionAnalysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene)
      : Base(config, scene), track_(scene) {}

  void sample() override {
    track_.sample();
    if constexpr (D == 2) sample_fields();
  }

  nlohmann::json result() const override;

 protected:
  /// "analysis/uz", "analysis/f" (the sampled fields with the tip) and the track.
  void declare_state(mpm::FieldList& list) override {
    if constexpr (D == 2) {
      const auto shape = node_field_shape(this->solver().global_grid());
      auto field = [](analysis::IntrusionFrame& f) -> analysis::GridField2D& { return f.field; };
      declare_field_frames(list, "uz", uz_frames_, shape, "m/s", field);
      declare_field_frames(list, "f", f_frames_, shape, "1", field);
    }
    track_.declare_fields(list);
  }

 private:
  /// u_z of the mixture (grains and fluid) and f of the grains on the nodes, with the tip
  /// (decomposed runs: on rank 0, from every rank's points).
  void sample_fields() {
    const double tip = body_tip(cfg_, scene_);
    with_every_point_on_root(this->solver(), [&] {
      if (comm::is_root()) sample_fields(tip);
    });
  }
  void sample_fields(double tip) {
    auto& solver = this->solver();
    std::vector<const mpm::Body<G>*> mix;
    for (int b : {scene_.grains, scene_.fluid})
      if (b >= 0) mix.push_back(&solver.body(b));
    analysis::IntrusionFrame uz;
    uz.time_s = solver.time_s();
    uz.tip_z_m = tip;
    uz.field =
        nodal_average<G>(solver.global_grid(), mix, [&](std::size_t b, std::int64_t p) { return mix[b]->v_m_s[p][1]; });
    uz_frames_.push_back(std::move(uz));
    if (scene_.grains >= 0 && scene_.granular_law) {
      const auto* law = scene_.granular_law;
      analysis::IntrusionFrame ff;
      ff.time_s = solver.time_s();
      ff.tip_z_m = tip;
      ff.field = nodal_average<G>(solver.global_grid(), {&solver.body(scene_.grains)},
                                  [&](std::size_t, std::int64_t p) { return law->f[static_cast<std::size_t>(p)]; });
      f_frames_.push_back(std::move(ff));
    }
  }

  BodyTrack<G> track_;
  std::vector<analysis::IntrusionFrame> uz_frames_, f_frames_;
};

template <class G>
nlohmann::json IntrusionAnalysis<G>::result() const {
  nlohmann::json out = nlohmann::json::object();
  const auto& track = track_.samples();
  if (track.size() < 2 || uz_frames_.empty()) return out;
  const scene::ThirdBody& tb = scene_.analysed_body();
  const double h = cfg_.grid.cell_size_m;
  const double sample_dt = track[1].t - track[0].t;
  const double v0 = tb.cfg->velocity_m_s[1];
  analysis::FrontGeometry geo;
  geo.direction = v0 < 0 ? -1.0 : 1.0;
  geo.intruder_radius_m = tb.cfg->max_m[0];
  geo.axis_r_m = cfg_.grid.origin_m[0];
  std::size_t window = 1;
  if (cfg_.analysis.filter_window_s > 0) {
    window = static_cast<std::size_t>(std::llround(cfg_.analysis.filter_window_s / sample_dt));
    if (window % 2 == 0) ++window;
  }
  analysis::FrontFitOptions fo;
  fo.wall_margin_m = 2.0 * h;
  // The bed bottom is the longitudinal wall. k_l, k_t are defined at constant v_0: an intruder
  // that ramps up to speed is fitted from the first sample whose (centred) time window lies
  // after its ramp.
  fo.t_begin_s =
      tb.cfg->ramp_time_s > 0 ? tb.cfg->ramp_time_s + 0.5 * static_cast<double>(window - 1) * sample_dt : 0.0;
  auto fronts = [&](const std::vector<analysis::IntrusionFrame>& frames, const analysis::FrontCriterion& crit) {
    nlohmann::json j;
    const auto series = analysis::measure_front_series(frames, crit, geo, window);
    j["series"] = analysis::to_json(series);
    try {
      const auto sp = analysis::front_speeds(series, std::fabs(v0), fo);
      j["speeds"] = analysis::to_json(sp);
    } catch (const InputError& e) {
      j["speeds"] = nullptr;
      j["fit_note"] = e.what();
    }
    // The advancing phase only (docs/analysis.md "Intrusion": a front that runs, then recedes).
    analysis::FrontFitOptions far = fo;
    far.to_farthest = true;
    try {
      j["speeds_to_farthest"] = analysis::to_json(analysis::front_speeds(series, std::fabs(v0), far));
    } catch (const InputError& e) {
      j["speeds_to_farthest"] = nullptr;
      j["fit_note_to_farthest"] = e.what();
    }
    return j;
  };
  nlohmann::json vel = fronts(uz_frames_, analysis::velocity_front(v0, cfg_.analysis.front_fraction));
  out["velocity_front"] = vel;
  if (!f_frames_.empty()) out["f_front"] = fronts(f_frames_, analysis::scalar_front(cfg_.analysis.f_threshold));
  nlohmann::json units;  // (of the top-level numbers: summary.json's "units", run/runner.cpp)
  const nlohmann::json& sp = vel["speeds"];
  const std::pair<const char*, const char*> speeds[] = {
      {"v_fl", "m/s"}, {"v_ft", "m/s"}, {"k_l", "1"}, {"k_t", "1"}, {"k_l_over_k_t", "1"}};
  for (const auto& [k, unit] : speeds) {
    out[k] = sp.is_null() ? nlohmann::json(nullptr) : sp[k];
    units[k] = unit;
  }
  const nlohmann::json& spf = vel["speeds_to_farthest"];
  for (const char* k : {"k_l", "k_t", "k_l_over_k_t"}) {
    out[std::string(k) + "_to_farthest"] = spf.is_null() ? nlohmann::json(nullptr) : spf[k];
    units[std::string(k) + "_to_farthest"] = "1";
  }
  out["v0"] = std::fabs(v0);
  units["v0"] = "m/s";
  out["ramp_time"] = tb.cfg->ramp_time_s;
  units["ramp_time"] = "s";
  out["filter_window_frames"] = window;
  units["filter_window_frames"] = "1";
  out["sample_interval"] = sample_dt;
  units["sample_interval"] = "s";
  out["units"] = units;
  return out;
}

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_intrusion_analysis(const scene::SceneConfig& config,
                                                          const scene::BuiltScene<G>& scene) {
  return std::make_unique<IntrusionAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_intrusion_analysis);

}  // namespace oobleck::run
