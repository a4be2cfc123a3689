#pragma once
// Parts of summary.json that every run has (docs/output.md "summary.json"): the resolved
// physical and numerical parameters, and the state of every [[body]] entry at the end.
#include <nlohmann/json.hpp>

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

}  // namespace oobleck::run
