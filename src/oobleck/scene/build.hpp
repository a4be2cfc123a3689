#pragma once
// A scene file's configuration (scene/config.hpp) turned into a ready MPM solver: the grid, the
// solver options, the walls, the regions' mixture or elastic bodies with their initial state
// (hydrostatic or suspended bed), the [[body]] entries (third_bodies.hpp) and the time step.
// The run loop (run/runner.cpp) and the scene analyses (run/analysis.hpp) read the result.
#include <memory>
#include <vector>

#include "oobleck/mpm/granular_body_law.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::scene {

/// A [[body]] entry in the solver.
struct ThirdBody {
  int body = -1;                    ///< body index in the solver
  int pair = -1;                    ///< its contact pair with the mixture
  int motor = -1;                   ///< its motor index (-1: none)
  const BodyConfig* cfg = nullptr;  ///< its entry in the scene configuration
};

/// The solver built from a scene and the handles the run and its analyses need.
template <class G>
struct BuiltScene {
  std::unique_ptr<mpm::Solver<G>> solver;
  int grains = -1;                                  ///< body index of the mixture's grains (-1: none)
  int fluid = -1;                                   ///< body index of the mixture's fluid (-1: none)
  mpm::GranularBodyLaw<G>* granular_law = nullptr;  ///< the grains' law (owned by their body)
  mpm::FluidLaw<G>* fluid_law = nullptr;            ///< the fluid's law (owned by its body)
  std::vector<ThirdBody> third;                     ///< the [[body]] entries, in file order
  int analysed = -1;                                ///< index into `third` of [analysis] body (intrusion, rod, wheel)
  double dt_s = 0.0;                                ///< the time step: time.dt, or the CFL-stable step
  long total_steps = 0;                             ///< round(duration / dt), at least 1

  const ThirdBody& analysed_body() const { return third[static_cast<std::size_t>(analysed)]; }
};

/// Build the solver of `config` (InputError naming the file and key for what cannot be built:
/// a region or body without points, an unstable time.dt, no wave speed to derive a step from).
template <class G>
BuiltScene<G> build_scene(const SceneConfig& config, int threads);

/// Top of the bed: the highest region of the mixture's phases along the last axis.
double bed_surface(const SceneConfig& config);

extern template BuiltScene<mpm::PlaneStrain> build_scene(const SceneConfig&, int);
extern template BuiltScene<mpm::Axisymmetric> build_scene(const SceneConfig&, int);
extern template BuiltScene<mpm::ThreeD> build_scene(const SceneConfig&, int);

}  // namespace oobleck::scene
