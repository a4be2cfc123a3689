#pragma once
// Nodal-field snapshots at analysis.snapshot_times (docs/output.md "Snapshots"; 2D grids):
// snapshot_<k>.csv with the mixture velocity, the grains' displacement since t = 0, f, p~ and phi
// on the physical nodes. The grains' initial positions are their body's reference positions
// (Body::x0_m, checkpointed with the body); the snapshot counter is the attribute "next_snapshot".
// Decomposed runs: the fields cover every rank's points; rank 0 writes the files.
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "oobleck/mpm/fields.hpp"
#include "oobleck/run/analysis.hpp"
#include "oobleck/scene/build.hpp"

namespace oobleck::run {

template <class G>
class Snapshots {
 public:
  /// Takes the grains' positions now as their initial positions (call before the first step).
  Snapshots(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene, std::string out_dir);

  /// Whether the next snapshot is due: its time is reached (within half a step), or this is the
  /// last step and the time lies within the run (times after the end of a shortened run are
  /// skipped; the last step takes a time within half a step of the end).
  bool due(bool final_step) const;
  /// Write the next snapshot's file and return its fields.
  SnapshotFields write_next();
  /// The files written so far (for summary.json "snapshots").
  std::vector<std::string> files() const;

  /// The attribute "next_snapshot" (mpm/fields.hpp).
  void declare_fields(mpm::FieldList& list);

 private:
  SnapshotFields fields() const;
  static std::string file_name(std::int64_t k) { return fmt::format("snapshot_{}.csv", k); }

  const scene::SceneConfig& cfg_;
  const scene::BuiltScene<G>& scene_;
  std::string out_dir_;
  std::int64_t next_ = 0;  ///< index of the next snapshot time
};

extern template class Snapshots<mpm::PlaneStrain>;
extern template class Snapshots<mpm::Axisymmetric>;
extern template class Snapshots<mpm::ThreeD>;

}  // namespace oobleck::run
