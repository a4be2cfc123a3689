#pragma once
// One scene measurement per [analysis] kind behind one interface (docs/analysis.md "In a run").
// The run loop (runner.cpp) calls the hooks at fixed moments and knows no kind:
//
//   after_step()       after every step (averages over the steps: settling)
//   sample()           at t = 0 of a fresh run, every analysis.sample_interval and at the last
//                      step (fields and body tracks: annular, intrusion, rod, wheel)
//   at_frame()         after each frame is written (the wheel's pressure scatter)
//   at_snapshot(s)     after each nodal-field snapshot (the rod's depth profile)
//   declare_fields     the sampled state as persistent fields (mpm/fields.hpp, group
//                      "analysis"), which the checkpoints write and restore, so that a restart
//                      reports what an uninterrupted run does
//   result()           the keys it adds to summary.json
//
// A new measurement is one new file analysis_<kind>.cpp with a make_<kind>_analysis function,
// declared in analysis_kinds.hpp and named in make_analysis (analysis.cpp).
#include <cstdint>
#include <memory>

#include <nlohmann/json.hpp>

#include "oobleck/analysis/data.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/scene/build.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::run {

/// Nodal fields of one snapshot (run/snapshots.hpp), 2D grids: mass-weighted bilinear averages.
struct SnapshotFields {
  double time_s = 0.0;
  analysis::GridField2D u_x, u_y;                        ///< mixture velocity [m/s]
  analysis::GridField2D displacement_x, displacement_y;  ///< grains since t = 0 [m]
  analysis::GridField2D f, p_grains;                     ///< structure, granular pressure [Pa]
};

template <class G>
class SceneAnalysis {
 public:
  /// `config` and `scene` outlive the analysis; it reads the solver and changes nothing in it.
  SceneAnalysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene) : cfg_(config), scene_(scene) {}
  virtual ~SceneAnalysis() = default;
  SceneAnalysis(const SceneAnalysis&) = delete;
  SceneAnalysis& operator=(const SceneAnalysis&) = delete;

  virtual void after_step() {}
  virtual void sample() {}
  virtual void at_frame() {}
  virtual void at_snapshot(const SnapshotFields&) {}
  /// Declare the analysis's persistent state (group "analysis"): the kind's own, then the
  /// settling sums, which "oobleck-checkpoint-1" keeps in every file (zero for the other kinds).
  void declare_fields(mpm::FieldList& list) {
    list.group("analysis");
    declare_state(list);
    list.add_attribute("settle_sum", settling_.sum, "m/s");
    list.add_attribute("settle_samples", settling_.samples, "1");
  }
  /// Keys for summary.json (an object; empty when there is nothing to report).
  virtual nlohmann::json result() const { return nlohmann::json::object(); }

 protected:
  /// The kind's sampled state (arrays, growing series, attributes).
  virtual void declare_state(mpm::FieldList&) {}
  /// The settling analysis's running sum of the settling velocity and its sample count.
  struct SettlingSums {
    double sum = 0.0;
    std::int64_t samples = 0;
  };
  SettlingSums settling_;

  mpm::Solver<G>& solver() const { return *scene_.solver; }
  const scene::SceneConfig& cfg_;
  const scene::BuiltScene<G>& scene_;
};

/// The analysis of `config.analysis.kind` (kind none: one that measures nothing).
template <class G>
std::unique_ptr<SceneAnalysis<G>> make_analysis(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene);

extern template std::unique_ptr<SceneAnalysis<mpm::PlaneStrain>> make_analysis(
    const scene::SceneConfig&, const scene::BuiltScene<mpm::PlaneStrain>&);
extern template std::unique_ptr<SceneAnalysis<mpm::Axisymmetric>> make_analysis(
    const scene::SceneConfig&, const scene::BuiltScene<mpm::Axisymmetric>&);
extern template std::unique_ptr<SceneAnalysis<mpm::ThreeD>> make_analysis(const scene::SceneConfig&,
                                                                          const scene::BuiltScene<mpm::ThreeD>&);

}  // namespace oobleck::run
