// [analysis] kind = "wheel" (S4, scenes.md; docs/analysis.md "Wheel"): the hub's height and the
// distance travelled along the periodic track, the motor's measured ω, and at every frame the
// point-to-point scatter of the grains' pressure under the wheel (the SI's ringing figure).
// Plane strain (x, y) and 3D (x, z: the height is the last axis; the scatter pools every y).
#include <cmath>

#include "oobleck/analysis/summary_json.hpp"
#include "oobleck/analysis/wheel.hpp"
#include "oobleck/run/analysis_kinds.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/run/body_track.hpp"
#include "oobleck/run/run_output.hpp"

namespace oobleck::run {

namespace {

template <class G>
class WheelAnalysis final : public SceneAnalysis<G> {
  static constexpr int D = G::dim;
  using Vd = mpm::Vec<D>;
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  WheelAnalysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene)
      : Base(config, scene), track_(scene) {}

  void sample() override { track_.sample(); }

  /// SI figure: how smooth the point pressure p~ = -tr(sigma)/3 of the grains is under the wheel.
  /// (Decomposed runs: measured on rank 0, from every rank's points.)
  void at_frame() override {
    if (scene_.grains < 0) return;
    const analysis::ScatterWindow window = scatter_window();
    with_every_point_on_root(this->solver(), [&] {
      if (!comm::is_root()) return;
      const auto& gb = this->solver().body(scene_.grains);
      std::vector<double> px, py, pp;
      for (std::int64_t p = 0; p < gb.size(); ++p) {
        px.push_back(gb.x_m[p][0]);
        py.push_back(gb.x_m[p][D - 1]);  // 3D: (x, z), every y
        pp.push_back(-gb.stress_Pa[p].trace() / 3.0);
      }
      const auto r = analysis::pressure_scatter(px, py, pp, window);
      if (r.points > 0) scatter_.push_back({this->solver().time_s(), r});  // else no grains under the wheel
    });
  }

  nlohmann::json result() const override;

 protected:
  /// "analysis/pressure_scatter" (one row of 6 per frame: t, relative, rms deviation, rms,
  /// points, cells) and the track.
  void declare_state(mpm::FieldList& list) override {
    list.add_series(
        "pressure_scatter", "rows of t [s], relative [1], rms deviation [Pa], rms [Pa], points [1], cells [1]",
        [this] {
          std::vector<double> flat;
          for (const auto& r : scatter_)
            flat.insert(flat.end(), {r.t, r.s.relative, r.s.rms_deviation_Pa, r.s.rms_Pa,
                                     static_cast<double>(r.s.points), static_cast<double>(r.s.cells)});
          return flat;
        },
        [this](const std::vector<double>& flat) {
          scatter_.clear();
          for (std::size_t o = 0; o + 6 <= flat.size(); o += 6) {
            ScatterSample r;
            r.t = flat[o];
            r.s.relative = flat[o + 1];
            r.s.rms_deviation_Pa = flat[o + 2];
            r.s.rms_Pa = flat[o + 3];
            r.s.points = static_cast<std::int64_t>(flat[o + 4]);
            r.s.cells = static_cast<std::int64_t>(flat[o + 5]);
            scatter_.push_back(r);
          }
        });
    track_.declare_fields(list);
  }

 private:
  struct ScatterSample {
    double t = 0.0;
    analysis::PressureScatter s;
  };

  double wheel_radius() const {
    const scene::BodyConfig& b = *scene_.analysed_body().cfg;
    return b.shape == scene::BodyShape::Disc ? b.radius_m : b.hub_radius_m + b.paddle_length_m;
  }

  /// Under the wheel: two radii either side of its centre of mass, from three radii below it to
  /// one above, on the grid's cells.
  analysis::ScatterWindow scatter_window() const {
    const auto& grid = this->solver().global_grid();
    const Vd c = centre_of_mass(this->solver(), scene_.analysed_body().body);
    const double R = wheel_radius();
    analysis::ScatterWindow w;
    w.x_centre_m = c[0];
    w.half_width_m = 2.0 * R;
    w.y_min_m = c[D - 1] - 3.0 * R;
    w.y_max_m = c[D - 1] + R;
    w.origin_x_m = grid.origin_m[0];
    w.origin_y_m = grid.origin_m[D - 1];
    w.cell_m = grid.h_m;
    w.period_m = cfg_.boundary[0].type == scene::BoundaryType::Periodic ? cfg_.grid.size_m[0] : 0.0;
    return w;
  }

  nlohmann::json scatter_result() const;

  BodyTrack<G> track_;
  std::vector<ScatterSample> scatter_;
};

template <class G>
nlohmann::json WheelAnalysis<G>::result() const {
  nlohmann::json out = nlohmann::json::object();
  const auto& track = track_.samples();
  if (track.size() < 2) return out;
  // S4 (scenes.md): hub (centre of mass) height and distance travelled vs time.
  analysis::HubTrack hub;
  for (const auto& t : track) {
    hub.time_s.push_back(t.t);
    hub.x_m.push_back(t.centre[0]);
    hub.y_m.push_back(t.centre[D - 1]);
  }
  analysis::WheelCriteria wc;
  wc.track_length_m = cfg_.grid.size_m[0];
  wc.wheel_radius_m = wheel_radius();
  wc.bed_surface_m = scene::bed_surface(cfg_);
  const double omega = scene_.analysed_body().cfg->motor_omega_rad_s.value_or(0.0);
  wc.forward = omega > 0 ? -1.0 : 1.0;  // counter-clockwise rotation rolls towards -x
  const auto sum = analysis::summarize_wheel(hub, wc);
  out.update(analysis::to_json(sum, wc));
  analysis::TimeSeries height, dist, om;
  for (std::size_t k = 0; k < track.size(); ++k) {
    height.time.push_back(track[k].t);
    height.value.push_back(track[k].centre[D - 1]);
    dist.time.push_back(track[k].t);
    dist.value.push_back(wc.forward * (sum.x_unwrapped_m[k] - sum.x_unwrapped_m[0]));
    om.time.push_back(track[k].t);
    om.value.push_back(track[k].omega);
  }
  out["hub_height"] = analysis::to_json(height);
  out["distance_travelled"] = analysis::to_json(dist);
  out["omega_measured"] = analysis::to_json(om);
  out["omega"] = omega;
  out["pressure_scatter"] = scatter_result();
  out["units"] = {{"omega", "rad/s"}};
  return out;
}

/// SI figure: the pressure scatter at every frame, and pooled over the frames after t = 0.
template <class G>
nlohmann::json WheelAnalysis<G>::scatter_result() const {
  auto scatter_json = [](const analysis::PressureScatter& r) {
    return nlohmann::json{{"relative", r.relative},
                          {"rms_deviation", r.rms_deviation_Pa},
                          {"rms", r.rms_Pa},
                          {"points", r.points},
                          {"cells", r.cells}};
  };
  nlohmann::json series = nlohmann::json::array();
  std::vector<analysis::PressureScatter> later;
  for (const auto& r : scatter_) {
    auto j = scatter_json(r.s);
    j["time"] = r.t;
    series.push_back(j);
    if (r.t > 0.0) later.push_back(r.s);
  }
  return {{"series", series}, {"pooled", scatter_json(analysis::pool(later))}};
}

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_wheel_analysis(const scene::SceneConfig& config,
                                                      const scene::BuiltScene<G>& scene) {
  return std::make_unique<WheelAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_wheel_analysis);

}  // namespace oobleck::run
