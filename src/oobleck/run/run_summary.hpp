#pragma once
// summary.json (docs/output.md "summary.json"): the whole summary of a run (run_summary), and the
// parts that every run has: the resolved physical and numerical parameters, and the state of
// every [[body]] entry at the end.
#include <nlohmann/json.hpp>

#include "oobleck/run/analysis.hpp"
#include "oobleck/run/snapshots.hpp"
#include "oobleck/scene/build.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::run {

/// "parameters": material, fluid, coupling, grid and transfer as the run used them. Each number's
/// unit goes to `units` under its dotted key ("parameters.rho_s": "kg/m^3"; summary.json's
/// "units").
nlohmann::json parameters(const scene::SceneConfig& config, nlohmann::json& units);

/// "bodies": per [[body]] entry its motion, points, whole mass (axisymmetric: 2 pi x per radian;
/// plane strain: per metre of depth), final centre, velocity and contact force of the last step;
/// the units of its scalars to `units` ("bodies.NAME.mass": "kg").
template <class G>
nlohmann::json bodies_summary(const scene::BuiltScene<G>& scene, nlohmann::json& units);

/// The whole summary.json of a run (docs/output.md "summary.json"): the scene, the points (per
/// body; decomposed: per rank, migrations, halo bytes), the steps and time, the wall time and
/// throughput, the step's timings, the parameters, the analysis's keys, the [[body]] entries and
/// the snapshots, with "units" for every number. `steps_run`: the steps of this run (a restart
/// counts from its checkpoint); `complete`: the run reached its end.
template <class G>
nlohmann::json run_summary(const scene::SceneConfig& cfg, const scene::BuiltScene<G>& scene,
                           const SceneAnalysis<G>& analysis, const Snapshots<G>& snapshots, long steps_run,
                           bool complete, double wall_s);

}  // namespace oobleck::run
