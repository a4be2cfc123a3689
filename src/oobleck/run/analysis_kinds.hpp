#pragma once
// The makers of the scene analyses, one per analysis_<kind>.cpp, for make_analysis (analysis.cpp).
#include <memory>

#include "oobleck/run/analysis.hpp"

namespace oobleck::run {

#define OOBLECK_ANALYSIS_MAKER(NAME) \
  template <class G>                 \
  std::unique_ptr<SceneAnalysis<G>> NAME(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene)

OOBLECK_ANALYSIS_MAKER(make_settling_analysis);
OOBLECK_ANALYSIS_MAKER(make_couette_analysis);
OOBLECK_ANALYSIS_MAKER(make_annular_analysis);
OOBLECK_ANALYSIS_MAKER(make_intrusion_analysis);
OOBLECK_ANALYSIS_MAKER(make_rod_analysis);
OOBLECK_ANALYSIS_MAKER(make_wheel_analysis);

/// Explicit instantiations of a maker for the three geometries (at the end of its file).
#define OOBLECK_INSTANTIATE_ANALYSIS_MAKER(NAME)                                                                \
  template std::unique_ptr<SceneAnalysis<mpm::PlaneStrain>> NAME(const scene::SceneConfig&,                     \
                                                                 const scene::BuiltScene<mpm::PlaneStrain>&);   \
  template std::unique_ptr<SceneAnalysis<mpm::Axisymmetric>> NAME(const scene::SceneConfig&,                    \
                                                                  const scene::BuiltScene<mpm::Axisymmetric>&); \
  template std::unique_ptr<SceneAnalysis<mpm::ThreeD>> NAME(const scene::SceneConfig&,                          \
                                                            const scene::BuiltScene<mpm::ThreeD>&)

}  // namespace oobleck::run
