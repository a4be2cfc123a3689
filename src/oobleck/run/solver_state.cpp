#include "oobleck/run/solver_state.hpp"

#include <cmath>
#include <string>
#include <type_traits>

#include <fmt/format.h>

namespace oobleck::run {

namespace {

/// Call f(name, array) for every per-point array of the bodies and laws that a restart needs
/// (the one list that save_solver_state stores and restore_solver_state reads back).
template <class G, class F>
void for_each_point_array(const scene::BuiltScene<G>& scene, F&& f) {
  auto& solver = *scene.solver;
  for (int b = 0; b < solver.body_count(); ++b) {
    auto& body = solver.body(b);
    const std::string p = fmt::format("body{}/", b);
    f(p + "mass", body.mass_kg);
    f(p + "volume", body.volume_m3);
    f(p + "volume0", body.volume0_m3);
    f(p + "x", as_doubles(body.x_m));
    f(p + "v", as_doubles(body.v_m_s));
    f(p + "C", as_doubles(body.C_1_s));
    f(p + "L", as_doubles(body.L_1_s));
    f(p + "stress", as_doubles(body.stress_Pa));
    f(p + "f_ext", as_doubles(body.f_ext_N));
    f(p + "phi", body.phi);
    f(p + "div_q", body.div_q_1_s);
  }
  if (auto* law = scene.granular_law) {
    f("granular/f", law->f);
    f("granular/regime", law->regime);
    f("granular/gamma_dot_p", law->gamma_dot_p);
  }
  if (auto* law = scene.fluid_law) f("fluid/ln_J", law->ln_J);
}

}  // namespace

template <class G>
void save_solver_state(io::CheckpointWriter& cp, const scene::BuiltScene<G>& scene) {
  constexpr int NC = G::ncomp;
  for_each_point_array(scene, [&](const std::string& name, auto&& a) { cp.array(name, a); });
  auto& solver = *scene.solver;
  for (std::size_t k = 0; k < scene.third.size(); ++k) {
    const auto& rm = solver.rigid_motion(scene.third[k].body);
    cp.array(fmt::format("third{}/rigid_velocity", k), std::span<const double>(rm.velocity_m_s.data(), NC));
    const mpm::Vec<NC> J = solver.contact(scene.third[k].pair).impulse_sum_N_s;
    cp.array(fmt::format("third{}/impulse_sum", k), std::span<const double>(J.data(), NC));
  }
}

template <class G>
void restore_solver_state(const io::Checkpoint& cp, const scene::BuiltScene<G>& scene) {
  constexpr int NC = G::ncomp;
  for_each_point_array(scene, [&](const std::string& name, auto&& a) {
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(a)>, std::vector<double>>) {
      if (name == "fluid/ln_J" && !cp.has(name) && cp.has("fluid/J")) {
        // A checkpoint of a version before the fluid's state became ln J: its J, in logarithms
        // (the continued run differs from an uninterrupted one by that logarithm's round-off).
        cp.read_into("fluid/J", a);
        for (double& x : a) x = std::log(x);
        return;
      }
    }
    cp.read_into(name, a);
  });
  auto& solver = *scene.solver;
  for (std::size_t k = 0; k < scene.third.size(); ++k) {
    auto& rm = solver.rigid_motion(scene.third[k].body);
    cp.read_into(fmt::format("third{}/rigid_velocity", k), std::span<double>(rm.velocity_m_s.data(), NC));
    mpm::Vec<NC> J;
    cp.read_into(fmt::format("third{}/impulse_sum", k), std::span<double>(J.data(), NC));
    solver.set_contact_impulse_sum(scene.third[k].pair, J);
  }
}

template void save_solver_state(io::CheckpointWriter&, const scene::BuiltScene<mpm::PlaneStrain>&);
template void save_solver_state(io::CheckpointWriter&, const scene::BuiltScene<mpm::Axisymmetric>&);
template void save_solver_state(io::CheckpointWriter&, const scene::BuiltScene<mpm::ThreeD>&);
template void restore_solver_state(const io::Checkpoint&, const scene::BuiltScene<mpm::PlaneStrain>&);
template void restore_solver_state(const io::Checkpoint&, const scene::BuiltScene<mpm::Axisymmetric>&);
template void restore_solver_state(const io::Checkpoint&, const scene::BuiltScene<mpm::ThreeD>&);

}  // namespace oobleck::run
