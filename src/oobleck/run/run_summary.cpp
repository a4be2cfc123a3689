#include "oobleck/run/run_summary.hpp"

#include <cmath>
#include <type_traits>
#include <vector>

#include "oobleck/core/build_info.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/rheology/parameter_table.hpp"
#include "oobleck/run/nodal_fields.hpp"

namespace oobleck::run {

nlohmann::json parameters(const scene::SceneConfig& config, nlohmann::json& units) {
  const int D = config.grid.dim;
  const auto& s = config.material.steady;
  nlohmann::json p;
  const auto put = [&](const char* key, nlohmann::json value, const char* unit) {
    p[key] = std::move(value);
    units[std::string("parameters.") + key] = unit;
  };
  p["preset"] = config.material.name;
  put("phi", config.regions.front().phi, "1");
  for (const rheology::Parameter& row : rheology::parameter_table()) {
    const std::string key(row.summary_key());
    const double v = row.section == rheology::Section::Fluid ? rheology::value(config.fluid, row)
                                                             : rheology::effective_value(config.material, row);
    put(key.c_str(), v, std::string(row.unit).c_str());
  }
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : s.eta_B_terms) terms.push_back({{"phi_i", t.phi_i}, {"alpha", t.alpha}});
  p["eta_B"] = terms;
  p["gravity"] = std::vector<double>(config.gravity_m_s2.begin(), config.gravity_m_s2.begin() + D);
  put("porosity_min", config.coupling.porosity_min, "1");
  p["drag"] = config.coupling.drag == scene::DragLaw::Beetstra ? "beetstra" : "carman_kozeny";
  put("cell_size", config.grid.cell_size_m, "m");
  p["cells"] = std::vector<int>(config.grid.cells.begin(), config.grid.cells.begin() + D);
  p["shape_function"] = scene::to_string(config.grid.shape);
  p["transfer"] = config.transfer.scheme == scene::TransferScheme::Apic ? "apic" : "flip";
  if (config.transfer.scheme == scene::TransferScheme::Flip) put("flip_fraction", config.transfer.flip_fraction, "1");
  if (config.grid.geometry == scene::Geometry::Axisymmetric) {
    put("r_inner", config.grid.origin_m[0], "m");
    put("r_outer", config.grid.origin_m[0] + config.grid.size_m[0], "m");
    put("height", config.grid.size_m[1], "m");
    if (config.boundary[0].type == scene::BoundaryType::Velocity)
      put("u_inner", config.boundary[0].velocity_m_s[2], "m/s");
  }
  return p;
}

template <class G>
nlohmann::json bodies_summary(const scene::BuiltScene<G>& scene, nlohmann::json& units) {
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
    const std::string at = "bodies." + tb.cfg->name + ".";
    units[at + "points"] = "1";
    units[at + "mass"] = std::is_same_v<G, mpm::PlaneStrain> ? "kg/m" : "kg";  // (axisymmetric: the whole body)
    if (tb.cfg->motion == scene::BodyMotionKind::Prescribed) {
      bodies[tb.cfg->name]["ramp_time"] = tb.cfg->ramp_time_s;
      units[at + "ramp_time"] = "s";
    }
  }
  return bodies;
}

template <class G>
nlohmann::json run_summary(const scene::SceneConfig& cfg, const scene::BuiltScene<G>& scene,
                           const SceneAnalysis<G>& analysis, const Snapshots<G>& snapshots, long steps_run,
                           bool complete, double wall_s) {
  mpm::Solver<G>& solver = *scene.solver;
  std::int64_t points = 0;
  nlohmann::json per_body;
  for (int b = 0; b < solver.body_count(); ++b) {
    points += solver.body(b).size();
    per_body[solver.body(b).name] = comm::sum(solver.body(b).size());
  }
  const std::int64_t own_points = points;
  points = comm::sum(points);
  const auto& tm = solver.timings();
  nlohmann::json j, units = nlohmann::json::object();  // units: {dotted key: unit} of the numbers
  const auto put = [&](const std::string& key, nlohmann::json value, const char* unit) {
    j[key] = std::move(value);
    units[key] = unit;
  };
  j["scene"] = cfg.name;
  j["scene_file"] = cfg.file;
  j["geometry"] = scene::to_string(cfg.grid.geometry);
  put("points", points, "1");
  j["points_per_body"] = per_body;
  for (const auto& b : per_body.items()) units["points_per_body." + b.key()] = "1";
  put("steps", solver.steps(), "1");
  put("steps_this_run", steps_run, "1");
  j["complete"] = complete;
  put("dt", scene.dt_s, "s");
  put("time", solver.time_s(), "s");
  put("wall_seconds", wall_s, "s");
  put("point_updates_per_second",
      wall_s > 0 ? static_cast<double>(points) * static_cast<double>(steps_run) / wall_s : 0.0, "1/s");
  put("threads", solver.threads(), "1");
  put("ranks", comm::size(), "1");
  if (const auto* dec = solver.decomposition()) {
    j["ranks_grid"] = dec->dims_string();
    j["points_per_rank"] = {{"min", comm::min(own_points)},
                            {"mean", static_cast<double>(points) / comm::size()},
                            {"max", comm::max(own_points)}};
    for (const char* k : {"min", "mean", "max"}) units[std::string("points_per_rank.") + k] = "1";
    put("points_migrated", comm::sum(solver.points_migrated()), "1");
    put("halo_bytes_sent_per_rank_per_step",
        steps_run > 0
            ? static_cast<double>(comm::sum(solver.halo_bytes_sent())) / comm::size() / static_cast<double>(steps_run)
            : 0.0,
        "1");
  }
  j["library_instruction_set"] = library_instruction_set();  // which CPU variant ran
  j["timings_seconds"] = {{"p2g", tm.p2g},
                          {"grid", tm.grid},
                          {"g2p", tm.g2p},
                          {"stress", tm.stress},
                          {"communication", comm::max(tm.communication)},
                          {"output_and_checks", wall_s - tm.total()}};
  for (const auto& t : j["timings_seconds"].items()) units["timings_seconds." + t.key()] = "s";
  j["parameters"] = parameters(cfg, units);
  nlohmann::json result = analysis.result();
  if (const auto u = result.find("units"); u != result.end()) {  // (its numbers' units)
    units.update(*u);
    result.erase(u);
  }
  j.update(result);
  if (!scene.third.empty()) j["bodies"] = bodies_summary(scene, units);
  if (!snapshots.files().empty()) j["snapshots"] = snapshots.files();
  j["units"] = units;  // (the scene analysis's keys: docs/analysis.md)
  return j;
}

template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::PlaneStrain>&, nlohmann::json&);
template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::Axisymmetric>&, nlohmann::json&);
template nlohmann::json bodies_summary(const scene::BuiltScene<mpm::ThreeD>&, nlohmann::json&);

#define OOBLECK_RUN_SUMMARY(G)                                                                                         \
  template nlohmann::json run_summary(const scene::SceneConfig&, const scene::BuiltScene<G>&, const SceneAnalysis<G>&, \
                                      const Snapshots<G>&, long, bool, double);
OOBLECK_RUN_SUMMARY(mpm::PlaneStrain)
OOBLECK_RUN_SUMMARY(mpm::Axisymmetric)
OOBLECK_RUN_SUMMARY(mpm::ThreeD)
#undef OOBLECK_RUN_SUMMARY

}  // namespace oobleck::run
