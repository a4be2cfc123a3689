#pragma once
// The solver's state in a checkpoint (format "oobleck-checkpoint-1"): the persistent fields that
// the bodies, their laws and the [[body]] entries declare (mpm/fields.hpp), one dataset
// "GROUP/NAME" each: per body b "body<b>/x", "v", "stress", "mass", "volume", "volume0", "C",
// "L", "f_ext", "phi", "div_q" (Body::declare_fields); the granular law's "granular/f",
// "granular/regime", "granular/gamma_dot_p"; the fluid law's "fluid/ln_J"; per [[body]] entry k
// "third<k>/rigid_velocity" and "third<k>/impulse_sum". The scene analyses and the snapshots add
// their own (run/analysis.hpp, run/snapshots.hpp).
#include <span>
#include <vector>

#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/scene/build.hpp"

namespace oobleck::run {

/// View a vector of fixed-size Eigen objects as doubles (they are stored without padding).
template <class T>
std::span<double> as_doubles(std::vector<T>& v) {
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "padded Eigen type");
  return {reinterpret_cast<double*>(v.data()), v.size() * static_cast<std::size_t>(T::SizeAtCompileTime)};
}
template <class T>
std::span<const double> as_doubles(const std::vector<T>& v) {
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "padded Eigen type");
  return {reinterpret_cast<const double*>(v.data()), v.size() * static_cast<std::size_t>(T::SizeAtCompileTime)};
}

/// The scene's persistent fields: every body's (with its law's), then every [[body]] entry's
/// rigid velocity and contact impulse sum. Views into the solver, valid while it is unchanged.
template <class G>
mpm::FieldList solver_fields(const scene::BuiltScene<G>& scene);

/// Write the bodies', laws' and [[body]] entries' state.
template <class G>
void save_solver_state(io::CheckpointWriter& cp, const scene::BuiltScene<G>& scene);
/// Read it back into the solver of the same scene (InputError when an array is missing or of
/// another size).
template <class G>
void restore_solver_state(const io::Checkpoint& cp, const scene::BuiltScene<G>& scene);

}  // namespace oobleck::run
