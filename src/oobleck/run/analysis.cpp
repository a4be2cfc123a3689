#include "oobleck/run/analysis.hpp"

#include "oobleck/run/analysis_kinds.hpp"

namespace oobleck::run {

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_analysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene) {
  switch (config.analysis.kind) {
    case scene::AnalysisKind::None: break;
    case scene::AnalysisKind::Settling: return make_settling_analysis<G>(config, scene);
    case scene::AnalysisKind::Couette: return make_couette_analysis<G>(config, scene);
    case scene::AnalysisKind::Annular: return make_annular_analysis<G>(config, scene);
    case scene::AnalysisKind::Intrusion: return make_intrusion_analysis<G>(config, scene);
    case scene::AnalysisKind::Rod: return make_rod_analysis<G>(config, scene);
    case scene::AnalysisKind::Wheel: return make_wheel_analysis<G>(config, scene);
  }
  return std::make_unique<SceneAnalysis<G>>(config, scene);  // measures nothing
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_analysis);

}  // namespace oobleck::run
