#include "oobleck/run/run_summary.hpp"

#include <cmath>
#include <type_traits>
#include <vector>

#include "oobleck/run/nodal_fields.hpp"

namespace oobleck::run {

nlohmann::json parameters(const scene::SceneConfig& config) {
  const int D = config.grid.dim;
  const auto& s = config.material.steady;
  const auto& g = config.material.granular;
  nlohmann::json p;
  p["preset"] = config.material.name;
  p["phi"] = config.regions.front().phi;
  p["rho_s"] = g.rho_s;
  p["rho_f"] = config.fluid.rho_f0_kg_m3;
  p["eta_0"] = config.fluid.eta_0_Pa_s;
  p["kappa"] = config.fluid.kappa_Pa;
  p["d"] = g.d;
  p["G"] = g.G;
  p["K"] = g.K;
  p["K_0"] = g.K_0;
  p["K_3"] = g.K_3;
  p["K_4"] = g.K_4;
  p["mu_1"] = s.mu_c;
  p["mu_2"] = g.mu_2 < 0 ? s.mu_c : g.mu_2;
  p["b"] = g.b;
  p["phi_c"] = s.phi_c;
  p["phi_j"] = s.phi_j;
  p["a_0"] = s.a_0;
  p["a_inf"] = s.a_inf;
  p["tau_star"] = s.tau_star;
  p["Delta"] = s.Delta;
  p["xi_dot_eps"] = s.xi_dot_eps;
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : s.eta_B_terms) terms.push_back({{"phi_i", t.phi_i}, {"alpha", t.alpha}});
  p["eta_B"] = terms;
  p["gravity"] = std::vector<double>(config.gravity_m_s2.begin(), config.gravity_m_s2.begin() + D);
  p["porosity_min"] = config.coupling.porosity_min;
  p["drag"] = config.coupling.drag == scene::DragLaw::Beetstra ? "beetstra" : "carman_kozeny";
  p["cell_size"] = config.grid.cell_size_m;
  p["cells"] = std::vector<int>(config.grid.cells.begin(), config.grid.cells.begin() + D);
  p["shape_function"] = scene::to_string(config.grid.shape);
  p["transfer"] = config.transfer.scheme == scene::TransferScheme::Apic ? "apic" : "flip";
  if (config.transfer.scheme == scene::TransferScheme::Flip) p["flip_fraction"] = config.transfer.flip_fraction;
  if (config.grid.geometry == scene::Geometry::Axisymmetric) {
    p["r_inner"] = config.grid.origin_m[0];
    p["r_outer"] = config.grid.origin_m[0] + config.grid.size_m[0];
    p["height"] = config.grid.size_m[1];
    if (config.boundary[0].type == scene::BoundaryType::Velocity) p["u_inner"] = config.boundary[0].velocity_m_s[2];
  }
  return p;
}

template <class G>
nlohmann::json bodies_summary(const scene::BuiltScene<G>& scene) {
  constexpr int D = G::dim, NC = G::ncomp;
  auto& solver = *scene.solver;
  nlohmann::json bodies = nlohmann::json::object();
  const double whole = std::is_same_v<G, mpm::Axisymmetric> ? 2.0 * M_PI : 1.0;
  for (const auto& tb : scene.third) {
    const BodyTotals<G> totals = body_totals(solver, tb.body);  // (decomposed: every rank's points)
    const mpm::Vec<D> c = centre_of_mass(solver, tb.body);
    const mpm::Vec<NC> v = totals.mean_velocity();
    const mpm::Vec<NC> F = solver.contact(tb.pair).force_N;
    bodies[tb.cfg->name] = {{"motion", scene::to_string(tb.cfg->motion)},
                            {"points", totals.points},
                            {"mass", whole * totals.mass_kg},
                            {"centre", std::vector<double>(c.data(), c.data() + D)},
                            {"velocity", std::vector<double>(v.data(), v.data() + NC)},
                            {"contact_force_last_step", std::vector<double>(F.data(), F.data() + NC)}};
    if (tb.cfg->motion == scene::BodyMotionKind::Prescribed) bodies[tb.cfg->name]["ramp_time"] = tb.cfg->ramp_time_s;
  }
  return bodies;
}

template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::PlaneStrain>&);
template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::Axisymmetric>&);
template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::ThreeD>&);

}  // namespace oobleck::run
