// [analysis] kind = "annular" (S1, scenes.md; docs/analysis.md "Annular shear"): at every sample
// the nodal mixture v_theta and the grains' structure f; in the summary the surface profiles at
// the paper's bob angles, the jammed (velocity) front and the structure front with their fitted
// speeds, the flow stop, the outer half's rotation, and whether the bob's speed admits a steady
// flow of the bed.
#include <algorithm>
#include <cmath>
#include <utility>

#include "oobleck/analysis/annular.hpp"
#include "oobleck/analysis/summary_json.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/run/analysis_kinds.hpp"
#include "oobleck/run/field_frames.hpp"
#include "oobleck/run/nodal_fields.hpp"

namespace oobleck::run {

namespace {

template <class G>
class AnnularAnalysis final : public SceneAnalysis<G> {
  static constexpr int D = G::dim;
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  using Base::Base;

  void sample() override {
    if constexpr (G::ncomp == 3 && D == 2) sample_frame();
  }

  nlohmann::json result() const override;

 protected:
  /// "analysis/shear" (v_theta) and "analysis/shear_f" (f, when sampled) of the frames.
  void declare_state(mpm::FieldList& list) override {
    if constexpr (D == 2) {
      const auto shape = node_field_shape(this->solver().global_grid());
      declare_field_frames(list, "shear", frames_, shape, "m/s",
                           [](analysis::ShearFrame& f) -> analysis::GridField2D& { return f.v_theta; });
      declare_field_frames(
          list, "shear_f", frames_, shape, "1", [](analysis::ShearFrame& f) -> analysis::GridField2D& { return f.f; },
          false);
    }
  }

 private:
  void sample_frame();
  analysis::AnnularGeometry geometry() const;
  nlohmann::json fronts_result(const analysis::AnnularGeometry& geo) const;
  nlohmann::json steady_flow_result(const analysis::AnnularGeometry& geo) const;
  nlohmann::json structure_front_result(const analysis::AnnularGeometry& geo) const;

  std::vector<analysis::ShearFrame> frames_;
};

/// Mass-weighted mixture v_theta on the physical nodes (r fastest), and f of the grains.
/// Decomposed runs: each node from its owner, f over every rank's points; on every rank.
template <class G>
void AnnularAnalysis<G>::sample_frame() {
  auto& solver = this->solver();
  const auto& local = solver.grid();
  const auto& grid = solver.global_grid();
  analysis::ShearFrame fr;
  fr.time_s = solver.time_s();
  fr.v_theta.origin_x = grid.origin_m[0];
  fr.v_theta.origin_y = grid.origin_m[1];
  fr.v_theta.h = grid.h_m;
  fr.v_theta.nx = static_cast<std::size_t>(grid.cells[0]) + 1;
  fr.v_theta.ny = static_cast<std::size_t>(grid.periodic[1] ? grid.cells[1] : grid.cells[1] + 1);
  std::vector<double> v_theta(static_cast<std::size_t>(local.node_count()), 0.0);  // on the local storage
  for (std::size_t flat = 0; flat < v_theta.size(); ++flat) {
    double m = 0.0, mv = 0.0;
    for (int b : {scene_.grains, scene_.fluid}) {
      if (b < 0) continue;
      const auto& fld = solver.field(b);
      m += fld.mass_kg[flat];
      mv += fld.mass_kg[flat] * fld.velocity[flat][2];
    }
    v_theta[flat] = m > 0 ? mv / m : 0.0;
  }
  fr.v_theta.values = physical_nodes_on_every_rank(solver, v_theta);
  if (scene_.grains >= 0 && scene_.granular_law) {  // the structure, for the structure front
    const auto* law = scene_.granular_law;
    fr.f = nodal_average<G>(
        grid, {&solver.body(scene_.grains)},
        [&](std::size_t, std::int64_t p) { return law->f[static_cast<std::size_t>(p)]; },
        solver.decomposition() != nullptr);
  }
  frames_.push_back(std::move(fr));
}

template <class G>
analysis::AnnularGeometry AnnularAnalysis<G>::geometry() const {
  analysis::AnnularGeometry g;
  g.bob_radius_m = cfg_.grid.origin_m[0];
  g.outer_radius_m = cfg_.grid.origin_m[0] + cfg_.grid.size_m[0];
  g.bob_speed_m_per_s = cfg_.boundary[0].velocity_m_s[2];
  double top = -INFINITY;
  for (const auto& r : cfg_.regions) top = std::max(top, r.max_m[D - 1]);
  g.sample_z_m = std::isfinite(cfg_.analysis.sample_z_m) ? cfg_.analysis.sample_z_m : top - 2.0 * cfg_.grid.cell_size_m;
  g.start_time_s = 0.0;
  return g;
}

template <class G>
nlohmann::json AnnularAnalysis<G>::result() const {
  nlohmann::json a = nlohmann::json::object();
  if (frames_.size() < 2) return a;
  // S1 (scenes.md): surface v_theta/u_i at 0, 0.1, 0.2, 0.31 rad of bob rotation, distance from
  // the Newtonian A r + B/r profile, jammed-front radius vs time and its speed, flow stop.
  const auto geo = geometry();
  std::vector<double> angles;
  const double max_angle = geo.bob_speed_m_per_s * frames_.back().time_s / geo.bob_radius_m;
  // The paper's angles, then later ones in longer runs (what the band does next).
  for (double th : {0.0, 0.1, 0.2, 0.31, 0.45, 0.6, 0.8, 1.0}) {
    if (th <= max_angle) angles.push_back(th);
  }
  const auto profiles = analysis::surface_profiles(frames_, geo, angles);
  a["profiles"] = analysis::to_json(profiles);
  nlohmann::json dist = nlohmann::json::array();
  for (const auto& pr : profiles) dist.push_back(analysis::newtonian_distance(pr, geo));
  a["newtonian_distance"] = dist;
  a["bob_angle_final_rad"] = max_angle;
  a.update(fronts_result(geo));
  a["steady_flow"] = steady_flow_result(geo);
  if (!frames_.front().f.values.empty()) a.update(structure_front_result(geo));
  // The units of the top-level numbers written (summary.json's "units", run/runner.cpp).
  const std::pair<const char*, const char*> units[] = {{"bob_angle_final_rad", "rad"},
                                                       {"front_farthest", "m"},
                                                       {"front_farthest_time", "s"},
                                                       {"front_speed", "m/s"},
                                                       {"flow_stop_time", "s"},
                                                       {"structure_front_threshold", "1"},
                                                       {"structure_front_wall_time", "s"},
                                                       {"structure_front_speed", "m/s"}};
  for (const auto& [key, unit] : units)
    if (a.contains(key)) a["units"][key] = unit;
  return a;
}

/// The jammed (co-rotating) front, its speed and the flow stop; the outer half's rotation.
template <class G>
nlohmann::json AnnularAnalysis<G>::fronts_result(const analysis::AnnularGeometry& geo) const {
  nlohmann::json a = nlohmann::json::object();
  const auto fronts = analysis::jammed_front_series(frames_, geo);
  // The front speed is fitted while the front advances: up to its farthest extent (after that
  // the co-rotation fades and the front criterion recedes, see docs/results.md).
  const auto radii = analysis::front_radius_series(fronts);
  a["front"] = analysis::to_json(radii);
  double t_farthest = INFINITY;
  if (radii.size() > 0) {
    const auto k =
        static_cast<std::size_t>(std::max_element(radii.value.begin(), radii.value.end()) - radii.value.begin());
    t_farthest = radii.time[k];
    a["front_farthest"] = radii.value[k];
    a["front_farthest_time"] = t_farthest;
  }
  try {
    analysis::FrontFitOptions fo;
    fo.wall_margin_m = cfg_.grid.cell_size_m;
    fo.t_end_s = t_farthest;
    const analysis::LinearFit fit = analysis::front_speed(fronts, geo, fo);
    a["front_speed"] = fit.slope;
    a["front_fit"] = analysis::to_json(fit);
  } catch (const InputError& e) {
    a["front_speed"] = nullptr;
    a["front_fit_note"] = e.what();
  }
  // The bob keeps turning, so flow stops when the jammed front reaches the outer wall (no velocity criterion).
  const auto stop = analysis::flow_stop_time(frames_, geo, 0.0, cfg_.grid.cell_size_m);
  a["flow_stop"] = analysis::to_json(stop);
  a["flow_stop_time"] = stop.time_s ? nlohmann::json(*stop.time_s) : nlohmann::json(nullptr);
  // The outer half's rotation relative to the bob and its arrest (below 10% of its peak).
  const auto outer = analysis::outer_rotation_series(frames_, geo);
  a["outer_rotation"] = analysis::to_json(outer);
  a["outer_arrest"] = analysis::to_json(analysis::outer_arrest(outer, 0.1));
  return a;
}

/// Whether the bob's speed admits a steady flow of the bed at its uniform phi (docs/analysis.md
/// "Annular shear"): the fastest steady shear of the flow curve, the simple bound it gives and
/// the exact 1D Couette limit (torque balance over the flow curve).
template <class G>
nlohmann::json AnnularAnalysis<G>::steady_flow_result(const analysis::AnnularGeometry& geo) const {
  nlohmann::json sf;
  const double phi = cfg_.regions.front().phi;
  sf["phi"] = phi;
  sf["bob_speed"] = geo.bob_speed_m_per_s;
  try {
    const auto& sp = cfg_.material.steady;
    const auto lim = rheology::fastest_steady_shear(sp, phi);
    const auto dst = rheology::shear_rate_dst(sp, phi);
    sf["shear_rate_dst"] = dst ? nlohmann::json(*dst) : nlohmann::json(nullptr);
    if (lim) {
      sf["max_shear_rate"] = lim->shear_rate;
      sf["max_shear_rate_stress"] = lim->attained ? nlohmann::json(lim->shear_stress) : nlohmann::json(nullptr);
      sf["max_shear_rate_is_dst_asymptote"] = !lim->attained;
      sf["bob_speed_bound"] = analysis::steady_bob_speed_limit(lim->shear_rate, geo);
      std::vector<double> tau, rate;
      for (const auto& pt : rheology::flow_curve(sp, phi, 4000)) {
        tau.push_back(pt.shear_stress);
        rate.push_back(pt.shear_rate);
      }
      const auto c = analysis::steady_couette_limit(tau, rate, geo);
      double limit = c.bob_speed_m_per_s;
      // tau_0 -> infinity on a DST asymptote: omega_bob -> gamma_dot_DST ln(r_o/r_0).
      if (dst) limit = std::max(limit, analysis::steady_bob_speed_limit(*dst, geo));
      sf["bob_speed_limit"] = limit;
      sf["bob_speed_limit_stress"] =
          limit > c.bob_speed_m_per_s ? nlohmann::json(nullptr) : nlohmann::json(c.bob_stress_Pa);
      sf["steady_flow_possible"] = std::fabs(geo.bob_speed_m_per_s) <= limit;
    } else {  // unbounded flow curve (CST): every bob speed has a steady state
      sf["max_shear_rate"] = nullptr;
      sf["bob_speed_bound"] = nullptr;
      sf["bob_speed_limit"] = nullptr;
      sf["steady_flow_possible"] = true;
    }
  } catch (const std::exception& e) {  // phi >= phi_j (jammed, no steady flow), or a failed solve
    sf["note"] = e.what();
    sf["steady_flow_possible"] = nullptr;
  }
  return sf;
}

/// How far the jammed structure has spread: f >= half its E9 limit f_m(phi) of the bed; its
/// radius series, when it comes within one cell of the outer wall, and its speed: a straight-line
/// fit of the radius over the frames before it comes within one cell of the wall (the structure
/// front does not recede, so no farthest-extent cut as for the velocity front).
template <class G>
nlohmann::json AnnularAnalysis<G>::structure_front_result(const analysis::AnnularGeometry& geo) const {
  nlohmann::json a = nlohmann::json::object();
  const double f_thr = 0.5 * rheology::f_m(cfg_.material.steady, cfg_.regions.front().phi);
  const auto sfronts = analysis::structure_front_series(frames_, geo, f_thr);
  a["structure_front"] = analysis::to_json(analysis::front_radius_series(sfronts));
  a["structure_front_threshold"] = f_thr;
  const auto t_wall = analysis::front_at_wall_time(sfronts, geo, cfg_.grid.cell_size_m);
  a["structure_front_wall_time"] = t_wall ? nlohmann::json(*t_wall) : nlohmann::json(nullptr);
  try {
    analysis::FrontFitOptions fo;
    fo.wall_margin_m = cfg_.grid.cell_size_m;
    const analysis::LinearFit fit = analysis::front_speed(sfronts, geo, fo);
    a["structure_front_speed"] = fit.slope;
    a["structure_front_fit"] = analysis::to_json(fit);
  } catch (const InputError& e) {
    a["structure_front_speed"] = nullptr;
    a["structure_front_fit_note"] = e.what();
  }
  return a;
}

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_annular_analysis(const scene::SceneConfig& config,
                                                        const scene::BuiltScene<G>& scene) {
  return std::make_unique<AnnularAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_annular_analysis);

}  // namespace oobleck::run
