// [analysis] kind = "rod" (S2, scenes.md; docs/analysis.md "Rod"): the free rod's position,
// velocity and acceleration (by finite differences of the position over the stencil
// filter_window, and from the contact force), peak deceleration, impact time, and |dz| vs depth
// below the rod at the first snapshot (Fig. 7c).
#include <cmath>
#include <type_traits>

#include "oobleck/analysis/rod.hpp"
#include "oobleck/analysis/summary_json.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/run/analysis_kinds.hpp"
#include "oobleck/run/body_track.hpp"

namespace oobleck::run {

namespace {

template <class G>
class RodAnalysis final : public SceneAnalysis<G> {
  static constexpr int D = G::dim;
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  RodAnalysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene)
      : Base(config, scene), track_(scene) {}

  void sample() override { track_.sample(); }

  void at_snapshot(const SnapshotFields& s) override {
    if (!profile_.is_null()) return;  // the first snapshot only
    // Fig. 7c: |dz| vs depth on the axis below the rod's tip.
    const double tip = body_tip(cfg_, scene_);
    const auto& grid = this->solver().global_grid();
    try {
      const auto prof = analysis::displacement_below_rod(s.displacement_y, tip, scene::bed_surface(cfg_), -1.0,
                                                         grid.origin_m[0], grid.origin_m[1] + cfg_.grid.cell_size_m);
      profile_ = analysis::to_json(prof);
      profile_["time"] = s.time_s;
      profile_["rod_tip"] = tip;
    } catch (const InputError& e) {
      profile_ = {{"note", e.what()}};
    }
  }

  nlohmann::json result() const override;

 protected:
  void declare_state(mpm::FieldList& list) override { track_.declare_fields(list); }

 private:
  BodyTrack<G> track_;
  nlohmann::json profile_;  ///< |dz| vs depth below the rod at the first snapshot (not checkpointed)
};

template <class G>
nlohmann::json RodAnalysis<G>::result() const {
  nlohmann::json out = nlohmann::json::object();
  const auto& track = track_.samples();
  if (track.size() < 2) return out;
  const scene::ThirdBody& tb = scene_.analysed_body();
  const double h = cfg_.grid.cell_size_m;
  const double sample_dt = track[1].t - track[0].t;
  const double g = std::fabs(cfg_.gravity_m_s2[D - 1]);
  const double M = this->solver().rigid_motion(tb.body).mass_kg;  // per radian, like the force
  analysis::TimeSeries zc, zb, Fz, vz;
  for (const auto& t : track) {
    zc.time.push_back(t.t);
    zc.value.push_back(t.centre[D - 1]);
    zb.time.push_back(t.t);
    zb.value.push_back(t.bottom - 0.5 * h / tb.cfg->points_per_cell);
    vz.time.push_back(t.t);
    vz.value.push_back(t.velocity[D - 1]);
  }
  for (std::size_t k = 1; k < track.size(); ++k) {  // force k: mean over (t_{k-1}, t_k]
    Fz.time.push_back(track[k].t);
    Fz.value.push_back(track[k].force[D - 1]);
  }
  std::size_t stencil = 1;
  if (cfg_.analysis.filter_window_s > 0)
    stencil =
        std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(cfg_.analysis.filter_window_s / sample_dt)));
  out["rod_position"] = analysis::to_json(zb);
  out["rod_centre"] = analysis::to_json(zc);
  out["rod_velocity"] = analysis::to_json(vz);
  out["contact_force"] = analysis::to_json(Fz);
  out["rod_mass"] = (std::is_same_v<G, mpm::Axisymmetric> ? 2.0 * M_PI : 1.0) * M;
  const auto a_force = analysis::acceleration_from_force(Fz, M, g);
  out["rod_acceleration_from_force"] = analysis::to_json(a_force);
  out["peak_deceleration_from_force"] = analysis::to_json(analysis::peak_deceleration(a_force, -1.0));
  if (zb.size() >= 2 * stencil + 1) {
    const auto kin = analysis::rod_kinematics(zb, stencil, analysis::DifferenceTime::midpoint);
    out["rod_velocity_from_position"] = analysis::to_json(kin.velocity);
    out["rod_acceleration"] = analysis::to_json(kin.acceleration);
    out["peak_deceleration"] = analysis::to_json(analysis::peak_deceleration(kin.acceleration, -1.0));
  }
  out["difference_stencil_samples"] = stencil;
  const double surface = scene::bed_surface(cfg_);
  out["bed_surface"] = surface;
  if (auto ti = analysis::impact_time_from_position(zb, surface, -1.0))
    out["impact_time"] = *ti;
  else
    out["impact_time"] = nullptr;
  out["final_depth"] = surface - zb.value.back();
  if (!profile_.is_null()) out["displacement_below_rod"] = profile_;
  out["final_velocity"] = vz.value.back();
  out["units"] = {{"rod_mass", std::is_same_v<G, mpm::PlaneStrain> ? "kg/m" : "kg"},  // (axisymmetric: whole rod)
                  {"difference_stencil_samples", "1"},
                  {"bed_surface", "m"},
                  {"impact_time", "s"},
                  {"final_depth", "m"},
                  {"final_velocity", "m/s"}};
  return out;
}

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_rod_analysis(const scene::SceneConfig& config,
                                                    const scene::BuiltScene<G>& scene) {
  return std::make_unique<RodAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_rod_analysis);

}  // namespace oobleck::run
