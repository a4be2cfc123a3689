#include "oobleck/run/solver_state.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <variant>

#include <fmt/format.h>

namespace oobleck::run {

template <class G>
mpm::FieldList solver_fields(const scene::BuiltScene<G>& scene) {
  auto& solver = *scene.solver;
  mpm::FieldList list;
  for (int b = 0; b < solver.body_count(); ++b) {
    list.group(fmt::format("body{}", b));
    solver.body(b).declare_fields(list);
  }
  for (int b = 0; b < solver.body_count(); ++b) {
    list.group(fmt::format("body{}", b));  // (the law's own group follows)
    if (auto& law = solver.body(b).law) law->declare_fields(solver.body(b), list);
  }
  for (std::size_t k = 0; k < scene.third.size(); ++k) {
    list.group(fmt::format("third{}", k));
    solver.rigid_motion(scene.third[k].body).declare_fields(list);
    solver.declare_contact_fields(scene.third[k].pair, list);
  }
  return list;
}

template <class G>
void save_solver_state(io::CheckpointWriter& cp, const scene::BuiltScene<G>& scene) {
  const mpm::FieldList list = solver_fields(scene);
  for (const mpm::PersistentField& f : list.fields()) {
    if (!f.in_checkpoint) continue;
    if (const auto* d = std::get_if<std::span<double>>(&f.data)) cp.array(f.dataset(), std::span<const double>(*d));
    if (const auto* u = std::get_if<std::span<std::uint8_t>>(&f.data))
      cp.array(f.dataset(), std::span<const std::uint8_t>(*u));
  }
}

template <class G>
void restore_solver_state(const io::Checkpoint& cp, const scene::BuiltScene<G>& scene) {
  const mpm::FieldList list = solver_fields(scene);
  for (const mpm::PersistentField& f : list.fields()) {
    if (!f.in_checkpoint) continue;
    const std::string legacy = f.group + "/" + f.legacy_name;
    if (const auto* d = std::get_if<std::span<double>>(&f.data)) {
      if (!f.legacy_name.empty() && !cp.has(f.dataset()) && cp.has(legacy)) {
        cp.read_into(legacy, *d);
        for (double& x : *d) x = f.from_legacy(x);
      } else {
        cp.read_into(f.dataset(), *d);
      }
    }
    if (const auto* u = std::get_if<std::span<std::uint8_t>>(&f.data)) cp.read_into(f.dataset(), *u);
  }
}

#define OOBLECK_INSTANTIATE_STATE(G)                                                   \
  template mpm::FieldList solver_fields(const scene::BuiltScene<G>&);                  \
  template void save_solver_state(io::CheckpointWriter&, const scene::BuiltScene<G>&); \
  template void restore_solver_state(const io::Checkpoint&, const scene::BuiltScene<G>&)
OOBLECK_INSTANTIATE_STATE(mpm::PlaneStrain);
OOBLECK_INSTANTIATE_STATE(mpm::Axisymmetric);
OOBLECK_INSTANTIATE_STATE(mpm::ThreeD);
#undef OOBLECK_INSTANTIATE_STATE

}  // namespace oobleck::run
