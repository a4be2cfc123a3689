#include "oobleck/run/run_output.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <variant>

#include <fmt/format.h>

#include "oobleck/core/comm.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/run/nodal_fields.hpp"
#include "oobleck/run/units.hpp"

namespace oobleck::run {

namespace {

/// Storage for a frame's per-field arrays (the frame holds spans into it).
class Arrays {
 public:
  explicit Arrays(std::size_t expected) { store_.reserve(expected); }
  std::vector<double>& add(std::size_t n) {
    store_.emplace_back(n, 0.0);
    return store_.back();
  }

 private:
  std::vector<std::vector<double>> store_;
};

/// Add field `f` (not the positions) to a frame's point cloud of n points, in `units`.
void add_to_cloud(io::PointCloud& cloud, const mpm::PersistentField& f, const std::string& units, std::size_t n,
                  Arrays& column) {
  const auto* d = std::get_if<std::span<double>>(&f.data);
  const std::string& name = f.shown_as();
  switch (f.frame) {
    case mpm::FrameForm::vector: cloud.vector(name, f.width, *d, units); return;
    case mpm::FrameForm::sym_tensor: {        // 3×3, column-major: (i, j) at i + 3 j
      const int idx[6] = {0, 3, 6, 4, 7, 8};  // xx xy xz yy yz zz
      std::array<std::vector<double>*, 6> c{};
      for (int k = 0; k < 6; ++k) {
        c[k] = &column.add(n);
        for (std::size_t p = 0; p < n; ++p) (*c[k])[p] = (*d)[9 * p + static_cast<std::size_t>(idx[k])];
      }
      cloud.sym_tensor(name, {*c[0], *c[1], *c[2], *c[3], *c[4], *c[5]}, units);
      return;
    }
    default: break;  // scalars
  }
  if (f.derive) {
    auto& values = column.add(n);
    f.derive(values);
    cloud.scalar(name, values, units);
  } else if (const auto* u = std::get_if<std::span<std::uint8_t>>(&f.data)) {
    auto& values = column.add(n);
    for (std::size_t p = 0; p < n; ++p) values[p] = (*u)[p];
    cloud.scalar(name, values, units);
  } else {
    cloud.scalar(name, *d, units);
  }
}

/// Body b's points with the fields that it and its law declare for frames (mpm/fields.hpp), each
/// in its declared unit in the points' measure (in_measure: "kg/rad" in axisymmetric runs).
template <class G>
io::PointCloud body_cloud(const scene::BuiltScene<G>& scene, int b, Arrays& column) {
  auto& body = scene.solver->body(b);
  const auto n = static_cast<std::size_t>(body.size());
  mpm::FieldList list;
  body.declare_fields(list);
  if (body.law) body.law->declare_fields(body, list);
  const std::vector<const mpm::PersistentField*> shown = list.frame_fields();  // (positions first)
  io::PointCloud cloud(body.name, shown.front()->width, std::get<std::span<double>>(shown.front()->data),
                       in_measure<G>(shown.front()->unit));
  for (std::size_t k = 1; k < shown.size(); ++k)
    add_to_cloud(cloud, *shown[k], in_measure<G>(shown[k]->unit), n, column);
  return cloud;
}

/// The solver's nodal frame fields (Solver::declare_grid_fields) on the physical nodes (x
/// fastest; decomposed: this rank's own box of them); nullopt when it declares none.
template <class G>
std::optional<io::NodeGrid> node_grid(const scene::BuiltScene<G>& scene, Arrays& column) {
  constexpr int D = G::dim;
  mpm::FieldList list;
  scene.solver->declare_grid_fields(list);
  const std::vector<const mpm::PersistentField*> shown = list.frame_fields();
  if (shown.empty()) return std::nullopt;
  const auto* dec = scene.solver->decomposition();
  const auto& local = scene.solver->grid();
  const auto& grid = dec ? dec->global() : local;
  std::array<std::size_t, 3> nodes{1, 1, 1};
  for (int a = 0; a < D; ++a) nodes[a] = static_cast<std::size_t>(grid.periodic[a] ? grid.cells[a] : grid.cells[a] + 1);
  std::array<double, 3> origin{0, 0, 0}, spacing{0, 0, 0};
  for (int a = 0; a < D; ++a) {
    origin[a] = grid.origin_m[a];
    spacing[a] = grid.h_m;
  }
  io::NodeGrid ng(D, origin, spacing, nodes);
  std::vector<std::size_t> at;  // the local flat index of each node written, x fastest
  if (dec) {
    const mpm::OwnedNodes box = mpm::owned_physical_nodes(*dec, local);
    std::array<std::size_t, 3> begin{}, extent{};
    for (int a = 0; a < 3; ++a) {
      begin[a] = static_cast<std::size_t>(box.begin[a]);
      extent[a] = static_cast<std::size_t>(box.extent[a]);
    }
    ng.set_part(begin, extent);
    mpm::for_owned_physical_nodes(*dec, local, [&](std::size_t flat, const auto&) { at.push_back(flat); });
  } else {
    for (std::size_t k = 0; k < nodes[2]; ++k)
      for (std::size_t j = 0; j < nodes[1]; ++j)
        for (std::size_t i = 0; i < nodes[0]; ++i) {
          const int logical[3] = {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
          int flat = 0;
          for (int a = 0; a < D; ++a) flat += local.storage_index(a, logical[a]) * local.stride(a);
          at.push_back(static_cast<std::size_t>(flat));
        }
  }
  for (const mpm::PersistentField* f : shown) {
    const auto& stored = std::get<std::span<double>>(f->data);
    auto& values = column.add(at.size());
    for (std::size_t n = 0; n < at.size(); ++n) values[n] = stored[at[n]];
    ng.scalar(f->shown_as(), values, in_measure<G>(f->unit));
  }
  return ng;
}

}  // namespace

template <class G>
void write_frame(io::FrameWriter& frames, const scene::BuiltScene<G>& scene) {
  auto& solver = *scene.solver;
  io::Frame frame;
  frame.time = solver.time_s();
  frame.step = solver.steps();
  Arrays column(64 * static_cast<std::size_t>(solver.body_count()) + 16);
  for (int b = 0; b < solver.body_count(); ++b) frame.bodies.push_back(body_cloud(scene, b, column));
  if (auto grid = node_grid(scene, column)) frame.grid = std::move(*grid);
  frames.write(frame);
}

template <class G>
Columns series_columns(const scene::BuiltScene<G>& scene) {
  constexpr int D = G::dim, NC = G::ncomp;
  auto& solver = *scene.solver;
  Columns c;
  c.add("time", "s");
  c.add("step", "1");
  for (int b = 0; b < solver.body_count(); ++b) {
    const std::string& n = solver.body(b).name;
    c.add("kinetic_energy_" + n, in_measure<G>("J"));
    for (int k = 0; k < NC; ++k) c.add(fmt::format("momentum_{}_{}", n, k), in_measure<G>("N s"));
    c.add("mass_" + n, in_measure<G>("kg"));
    c.add("max_speed_" + n, "m/s");
  }
  for (const auto& tb : scene.third) {
    const std::string& n = tb.cfg->name;
    for (int k = 0; k < D; ++k) c.add(fmt::format("centre_{}_{}", n, k), "m");
    for (int k = 0; k < NC; ++k) c.add(fmt::format("contact_force_{}_{}", n, k), in_measure<G>("N"));
    if (tb.motor >= 0) {
      c.add("omega_" + n, "rad/s");
      c.add("motor_torque_" + n, in_measure<G>("N m"));
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
  if (solver.decomposition()) {  // every rank's points: sums, and the largest speed
    std::vector<double> sums;
    for (int b = 0; b < solver.body_count(); ++b) {
      const std::size_t at = 2 + static_cast<std::size_t>(b) * (NC + 3);
      sums.insert(sums.end(), r.begin() + static_cast<long>(at), r.begin() + static_cast<long>(at + NC + 2));
      r[at + NC + 2] = comm::max(r[at + NC + 2]);
    }
    comm::sum(sums);
    for (int b = 0; b < solver.body_count(); ++b)
      std::copy_n(sums.begin() + static_cast<long>(b) * (NC + 2), NC + 2,
                  r.begin() + static_cast<long>(2 + static_cast<std::size_t>(b) * (NC + 3)));
  }
  for (const auto& tb : scene.third) {
    const mpm::Vec<D> c = centre_of_mass(solver, tb.body);  // (decomposed: every rank's points)
    for (int k = 0; k < D; ++k) r.push_back(c[k]);
    const mpm::Vec<NC> F = solver.contact(tb.pair).force_N;
    for (int k = 0; k < NC; ++k) r.push_back(F[k]);
    if (tb.motor >= 0) {
      r.push_back(solver.motor(tb.motor).omega_measured_rad_s);
      r.push_back(solver.motor(tb.motor).torque_N_m);
    }
  }
  return r;
}

#define OOBLECK_INSTANTIATE_OUTPUT(G)                                       \
  template void write_frame(io::FrameWriter&, const scene::BuiltScene<G>&); \
  template Columns series_columns(const scene::BuiltScene<G>&);             \
  template std::vector<double> series_row(const scene::BuiltScene<G>&)
OOBLECK_INSTANTIATE_OUTPUT(mpm::PlaneStrain);
OOBLECK_INSTANTIATE_OUTPUT(mpm::Axisymmetric);
OOBLECK_INSTANTIATE_OUTPUT(mpm::ThreeD);
#undef OOBLECK_INSTANTIATE_OUTPUT

}  // namespace oobleck::run
