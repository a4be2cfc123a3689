#pragma once
// The run's state in a checkpoint (format "oobleck-checkpoint-1", docs/output.md): the
// persistent fields that its parts declare (mpm/fields.hpp), written and restored by one loop.
// The parts, in declaration order:
//   solver_fields       per body b "body<b>/x", "v", "stress", "mass", "volume", "volume0", "C",
//                       "L", "f_ext", "phi", "div_q" and, with snapshots, the grains' "x0"
//                       (Body::declare_fields); the granular law's
//                       "granular/f", "granular/regime", "granular/gamma_dot_p"; the fluid law's
//                       "fluid/ln_J"; per [[body]] entry k "third<k>/rigid_velocity" and
//                       "third<k>/impulse_sum"
//   Snapshots           attribute "next_snapshot" (run/snapshots.hpp)
//   SceneAnalysis       its samples under "analysis/" and attributes (run/analysis.hpp)
#include <functional>
#include <string>

#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/scene/build.hpp"

namespace oobleck::run {

/// The scene's solver fields: every body's (with its law's), then every [[body]] entry's rigid
/// velocity and contact impulse sum. Views into the solver, valid while it is unchanged.
template <class G>
mpm::FieldList solver_fields(const scene::BuiltScene<G>& scene);

/// Write every field of `list` that belongs in a checkpoint: arrays as flat datasets, growing
/// series when not empty, numbers as attributes. A decomposed run calls it on every rank with
/// a writer of every rank: the points' arrays hold every rank's points (rank order), the others
/// are rank 0's. Each dataset's `units` attribute is units(the field's declared unit) (the run
/// passes in_measure<G>, run/units.hpp).
void save_fields(io::CheckpointWriter& cp, const mpm::FieldList& list,
                 const std::function<std::string(const char*)>& units);

/// Read them back in place: an array or attribute the checkpoint lacks, or an array of another
/// size or type, is an InputError naming the file and the dataset (an array with a
/// `legacy_name` is read from that older dataset when only it is there); a growing series is
/// unpacked when the checkpoint has it.
void restore_fields(const io::Checkpoint& cp, const mpm::FieldList& list);

}  // namespace oobleck::run
