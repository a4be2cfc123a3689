#include "oobleck/run/checkpoint_state.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

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

void save_fields(io::CheckpointWriter& cp, const mpm::FieldList& list,
                 const std::function<std::string(const char*)>& units) {
  for (const mpm::PersistentField& f : list.fields()) {
    if (!f.in_checkpoint) continue;
    const std::string name = f.dataset();
    const std::string unit = units(f.unit);
    std::visit(
        [&](const auto& d) {
          using T = std::decay_t<decltype(d)>;
          if constexpr (std::is_same_v<T, std::span<double>> || std::is_same_v<T, std::span<std::uint8_t>>) {
            using V = std::span<const typename T::value_type>;
            if (f.per_point) {
              cp.ranks_array(name, V(d), unit);  // (decomposed: every rank's points)
            } else {
              cp.array(name, V(d), {}, unit);
            }
          } else if constexpr (std::is_same_v<T, mpm::GrowingSeries>) {
            const std::vector<double> values = d.pack();
            if (!values.empty()) cp.array(name, values, {}, unit);
          } else if constexpr (std::is_same_v<T, double*> || std::is_same_v<T, std::int64_t*>) {
            cp.attribute(name, *d);
          }
        },
        f.data);
  }
}

void restore_fields(const io::Checkpoint& cp, const mpm::FieldList& list) {
  for (const mpm::PersistentField& f : list.fields()) {
    if (!f.in_checkpoint) continue;
    const std::string name = f.dataset();
    std::visit(
        [&](const auto& d) {
          using T = std::decay_t<decltype(d)>;
          if constexpr (std::is_same_v<T, std::span<double>>) {
            // (a legacy name starting with '/' names a dataset of another group)
            const std::string legacy =
                f.legacy_name.starts_with('/') ? f.legacy_name.substr(1) : f.group + "/" + f.legacy_name;
            if (!f.legacy_name.empty() && !cp.has(name) && cp.has(legacy)) {
              cp.read_into(legacy, d);
              for (double& x : d) x = f.from_legacy(x);
            } else {
              cp.read_into(name, d);
            }
          } else if constexpr (std::is_same_v<T, std::span<std::uint8_t>>) {
            cp.read_into(name, d);
          } else if constexpr (std::is_same_v<T, mpm::GrowingSeries>) {
            if (!cp.has(name)) return;
            try {
              d.unpack(cp.doubles(name));
            } catch (const InputError& e) {
              throw InputError(fmt::format("{}: '{}': {}", cp.file(), name, e.what()));
            }
          } else if constexpr (std::is_same_v<T, double*>) {
            *d = cp.real_attribute(name);
          } else if constexpr (std::is_same_v<T, std::int64_t*>) {
            *d = cp.int_attribute(name);
          }
        },
        f.data);
  }
}

template mpm::FieldList solver_fields(const scene::BuiltScene<mpm::PlaneStrain>&);
template mpm::FieldList solver_fields(const scene::BuiltScene<mpm::Axisymmetric>&);
template mpm::FieldList solver_fields(const scene::BuiltScene<mpm::ThreeD>&);

}  // namespace oobleck::run
