#include "oobleck/run/run_output.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include <fmt/format.h>

#include "oobleck/material/granular.hpp"
#include "oobleck/run/nodal_fields.hpp"

namespace oobleck::run {

namespace {

/// Storage for a frame's per-field arrays (the frame holds spans into it).
class Columns {
 public:
  explicit Columns(std::size_t expected) { store_.reserve(expected); }
  std::vector<double>& add(std::size_t n) {
    store_.emplace_back(n, 0.0);
    return store_.back();
  }

 private:
  std::vector<std::vector<double>> store_;
};

/// Body b's points with their fields.
template <class G>
io::PointCloud body_cloud(const scene::BuiltScene<G>& scene, int b, Columns& column) {
  constexpr int D = G::dim, NC = G::ncomp;
  const auto& body = scene.solver->body(b);
  const auto n = static_cast<std::size_t>(body.size());
  std::array<std::vector<double>*, 3> pos{};
  for (int a = 0; a < D; ++a) {
    pos[a] = &column.add(n);
    for (std::size_t p = 0; p < n; ++p) (*pos[a])[p] = body.x_m[p][a];
  }
  io::PointCloud cloud = D == 2 ? io::PointCloud(body.name, {*pos[0], *pos[1]})
                                : io::PointCloud(body.name, {*pos[0], *pos[1], *pos[2]});
  std::array<std::vector<double>*, 3> vel{};
  for (int c = 0; c < NC; ++c) {
    vel[c] = &column.add(n);
    for (std::size_t p = 0; p < n; ++p) (*vel[c])[p] = body.v_m_s[p][c];
  }
  if (NC == 2) cloud.vector("velocity", {*vel[0], *vel[1]});
  else cloud.vector("velocity", {*vel[0], *vel[1], *vel[2]});
  std::array<std::vector<double>*, 6> s6{};
  const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int k = 0; k < 6; ++k) {
    s6[k] = &column.add(n);
    for (std::size_t p = 0; p < n; ++p) (*s6[k])[p] = body.stress_Pa[p](idx[k][0], idx[k][1]);
  }
  cloud.sym_tensor("stress", {*s6[0], *s6[1], *s6[2], *s6[3], *s6[4], *s6[5]});
  auto& pressure = column.add(n);
  for (std::size_t p = 0; p < n; ++p) pressure[p] = -body.stress_Pa[p].trace() / 3.0;
  cloud.scalar(b == scene.fluid ? "fluid_pressure" : "pressure", pressure);
  cloud.scalar("mass", body.mass_kg).scalar("volume", body.volume_m3);
  if (b == scene.grains) {
    auto& law = *scene.granular_law;
    auto& phi = column.add(n);
    auto& tau = column.add(n);
    auto& regime = column.add(n);
    for (std::size_t p = 0; p < n; ++p) {
      phi[p] = law.phi_of(body, static_cast<std::int64_t>(p));
      tau[p] = material::tau_bar(body.stress_Pa[p]);
      regime[p] = law.regime[p];
    }
    cloud.scalar("f", law.f).scalar("phi", phi).scalar("tau_bar", tau);
    cloud.scalar("regime", regime).scalar("gamma_dot_p", law.gamma_dot_p);
  }
  if (b == scene.fluid) {
    auto& J = column.add(n);  // (the frames show J = ρ_f0/ρ_f; the law's state is ln J)
    for (std::size_t p = 0; p < n; ++p) J[p] = std::exp(scene.fluid_law->ln_J[p]);
    cloud.scalar("phi", body.phi).scalar("J", J);
  }
  return cloud;
}

/// Nodal porosity on the physical nodes (x fastest).
template <class G>
io::NodeGrid porosity_grid(const scene::BuiltScene<G>& scene, Columns& column) {
  constexpr int D = G::dim;
  const auto& n_nodal = scene.solver->nodal_porosity();
  const auto& grid = scene.solver->grid();
  std::array<std::size_t, 3> nodes{1, 1, 1};
  for (int a = 0; a < D; ++a) nodes[a] = static_cast<std::size_t>(grid.periodic[a] ? grid.cells[a] : grid.cells[a] + 1);
  auto& values = column.add(nodes[0] * nodes[1] * nodes[2]);
  for (std::size_t k = 0; k < nodes[2]; ++k) {
    for (std::size_t j = 0; j < nodes[1]; ++j) {
      for (std::size_t i = 0; i < nodes[0]; ++i) {
        const int logical[3] = {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
        int flat = 0;
        for (int a = 0; a < D; ++a) flat += grid.storage_index(a, logical[a]) * grid.stride(a);
        values[i + nodes[0] * (j + nodes[1] * k)] = n_nodal[static_cast<std::size_t>(flat)];
      }
    }
  }
  std::array<double, 3> origin{0, 0, 0}, spacing{0, 0, 0};
  for (int a = 0; a < D; ++a) {
    origin[a] = grid.origin_m[a];
    spacing[a] = grid.h_m;
  }
  io::NodeGrid ng(D, origin, spacing, nodes);
  ng.scalar("porosity", values);
  return ng;
}

}  // namespace

template <class G>
void write_frame(io::FrameWriter& frames, const scene::BuiltScene<G>& scene) {
  const auto& solver = *scene.solver;
  io::Frame frame;
  frame.time = solver.time_s();
  frame.step = solver.steps();
  Columns column(64 * static_cast<std::size_t>(solver.body_count()) + 16);
  for (int b = 0; b < solver.body_count(); ++b) frame.bodies.push_back(body_cloud(scene, b, column));
  if (!solver.nodal_porosity().empty()) frame.grid = porosity_grid(scene, column);
  frames.write(frame);
}

template <class G>
std::vector<std::string> series_columns(const scene::BuiltScene<G>& scene) {
  constexpr int D = G::dim, NC = G::ncomp;
  auto& solver = *scene.solver;
  std::vector<std::string> c = {"time", "step"};
  for (int b = 0; b < solver.body_count(); ++b) {
    const std::string& n = solver.body(b).name;
    c.push_back("kinetic_energy_" + n);
    for (int k = 0; k < NC; ++k) c.push_back(fmt::format("momentum_{}_{}", n, k));
    c.push_back("mass_" + n);
    c.push_back("max_speed_" + n);
  }
  for (const auto& tb : scene.third) {
    const std::string& n = tb.cfg->name;
    for (int k = 0; k < D; ++k) c.push_back(fmt::format("centre_{}_{}", n, k));
    for (int k = 0; k < NC; ++k) c.push_back(fmt::format("contact_force_{}_{}", n, k));
    if (tb.motor >= 0) {
      c.push_back("omega_" + n);
      c.push_back("motor_torque_" + n);
    }
  }
  return c;
}

template <class G>
std::vector<double> series_row(const scene::BuiltScene<G>& scene) {
  constexpr int D = G::dim, NC = G::ncomp;
  auto& solver = *scene.solver;
  std::vector<double> r = {solver.time_s(), static_cast<double>(solver.steps())};
  for (int b = 0; b < solver.body_count(); ++b) {
    const auto& body = solver.body(b);
    r.push_back(body.kinetic_energy());
    const mpm::Vec<NC> P = body.total_momentum();
    for (int k = 0; k < NC; ++k) r.push_back(P[k]);
    r.push_back(body.total_mass());
    double vmax = 0.0;
    for (const auto& v : body.v_m_s) vmax = std::max(vmax, v.norm());
    r.push_back(vmax);
  }
  for (const auto& tb : scene.third) {
    const mpm::Vec<D> c = centre_of_mass(solver.body(tb.body), solver.grid());
    for (int k = 0; k < D; ++k) r.push_back(c[k]);
    const mpm::Vec<NC> F = solver.contact(tb.pair).force_N;
    for (int k = 0; k < NC; ++k) r.push_back(F[k]);
    if (tb.motor >= 0) {
      if constexpr (std::is_same_v<G, mpm::PlaneStrain>) {
        r.push_back(solver.motor(tb.motor).omega_measured_rad_s);
        r.push_back(solver.motor(tb.motor).torque_N_m);
      }
    }
  }
  return r;
}

#define OOBLECK_INSTANTIATE_OUTPUT(G)                                                  \
  template void write_frame(io::FrameWriter&, const scene::BuiltScene<G>&);            \
  template std::vector<std::string> series_columns(const scene::BuiltScene<G>&);       \
  template std::vector<double> series_row(const scene::BuiltScene<G>&)
OOBLECK_INSTANTIATE_OUTPUT(mpm::PlaneStrain);
OOBLECK_INSTANTIATE_OUTPUT(mpm::Axisymmetric);
OOBLECK_INSTANTIATE_OUTPUT(mpm::ThreeD);
#undef OOBLECK_INSTANTIATE_OUTPUT

}  // namespace oobleck::run
