#include "oobleck/run/snapshots.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "oobleck/io/output_file.hpp"
#include "oobleck/run/nodal_fields.hpp"

namespace oobleck::run {

template <class G>
Snapshots<G>::Snapshots(const scene::SceneConfig& config, const scene::BuiltScene<G>& scene, std::string out_dir)
    : cfg_(config), scene_(scene), out_dir_(std::move(out_dir)) {
  // The grains' reference positions live in their body (a per-point array that migrates with the
  // points of a decomposed run), and only where snapshots are taken (2D grids).
  if (scene.grains >= 0 && G::dim == 2 && !config.analysis.snapshot_times_s.empty()) {
    mpm::Body<G>& grains = scene.solver->body(scene.grains);
    grains.keeps_x0 = true;
    grains.x0_m = grains.x_m;
  }
}

template <class G>
bool Snapshots<G>::due(bool final_step) const {
  if constexpr (G::dim != 2) {
    (void)final_step;
    return false;  // the configuration allows snapshot_times on 2D grids only
  } else {
    const auto& times = cfg_.analysis.snapshot_times_s;
    const auto next = static_cast<std::size_t>(next_);
    return next < times.size() && (scene_.solver->time_s() >= times[next] - 0.5 * scene_.dt_s ||
                                   (final_step && times[next] <= cfg_.time.duration_s));
  }
}

/// Nodal fields (bilinear, mass-weighted): mixture velocity, grain displacement since t = 0,
/// structure f, granular pressure p~ (zero without grains). Decomposed runs: over every rank's
/// points, on every rank.
template <class G>
SnapshotFields Snapshots<G>::fields() const {
  SnapshotFields s;
  if constexpr (G::dim == 2) {
    auto& solver = *scene_.solver;
    s.time_s = solver.time_s();
    std::vector<const mpm::Body<G>*> mix;
    for (int b : {scene_.grains, scene_.fluid})
      if (b >= 0) mix.push_back(&solver.body(b));
    const auto& grid = solver.global_grid();
    const bool across = solver.decomposition() != nullptr;
    auto vel = [&](int c) {
      return nodal_average<G>(
          grid, mix, [&](std::size_t b, std::int64_t p) { return mix[b]->v_m_s[p][c]; }, across);
    };
    s.u_x = vel(0);
    s.u_y = vel(1);
    if (scene_.grains >= 0) {
      const auto& gb = solver.body(scene_.grains);
      const auto* law = scene_.granular_law;
      const std::vector<const mpm::Body<G>*> gs = {&gb};
      auto displacement = [&](int a) {
        return nodal_average<G>(
            grid, gs,
            [&](std::size_t, std::int64_t p) {
              return mpm::periodic_difference<2>(grid, gb.x_m[p], gb.x0_m[static_cast<std::size_t>(p)])[a];
            },
            across);
      };
      s.displacement_x = displacement(0);
      s.displacement_y = displacement(1);
      s.f = nodal_average<G>(
          grid, gs, [&](std::size_t, std::int64_t p) { return law->f[static_cast<std::size_t>(p)]; }, across);
      s.p_grains = nodal_average<G>(
          grid, gs, [&](std::size_t, std::int64_t p) { return -gb.stress_Pa[p].trace() / 3.0; }, across);
    } else {
      s.displacement_x = s.u_x;
      std::fill(s.displacement_x.values.begin(), s.displacement_x.values.end(), 0.0);
      s.displacement_y = s.f = s.p_grains = s.displacement_x;
    }
  }
  return s;
}

template <class G>
SnapshotFields Snapshots<G>::write_next() {
  SnapshotFields s = fields();
  if constexpr (G::dim == 2) {
    auto& solver = *scene_.solver;
    // phi = 1 - the step's nodal porosity (0 without a mixture).
    const auto& stored = solver.nodal_porosity();
    const std::vector<double> n_nodal =
        stored.empty() ? std::vector<double>{} : physical_nodes_on_every_rank(solver, stored);
    if (!comm::is_root()) {  // (decomposed: rank 0 writes the file)
      ++next_;
      return s;
    }
    // The columns with their units: "units: x=m, ..." ends the comment line, then the header.
    const std::pair<const char*, const char*> columns[] = {{"x", "m"},
                                                           {"y", "m"},
                                                           {"u_x", "m/s"},
                                                           {"u_y", "m/s"},
                                                           {"displacement_x", "m"},
                                                           {"displacement_y", "m"},
                                                           {"f", "1"},
                                                           {"p_grains", "Pa"},
                                                           {"phi", "1"}};
    std::string units = "units: ", header;
    for (const auto& [name, unit] : columns) {
      units += fmt::format("{}{}={}", header.empty() ? "" : ", ", name, unit);
      header += fmt::format("{}{}", header.empty() ? "" : ",", name);
    }
    std::string text = header + "\n";
    for (std::size_t j = 0; j < s.u_x.ny; ++j) {
      for (std::size_t i = 0; i < s.u_x.nx; ++i) {
        const std::size_t k = j * s.u_x.nx + i;
        const double phi = n_nodal.empty() ? 0.0 : 1.0 - n_nodal[k];
        text += fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", s.u_x.x(i), s.u_x.y(j),
                            s.u_x.values[k], s.u_y.values[k], s.displacement_x.values[k], s.displacement_y.values[k],
                            s.f.values[k], s.p_grains.values[k], phi);
      }
    }
    io::write_file_atomically(
        out_dir_ + "/" + file_name(next_),
        fmt::format("# t = {:.9g} s (requested {:.9g} s), step {}; {}\n", solver.time_s(),
                    cfg_.analysis.snapshot_times_s[static_cast<std::size_t>(next_)], solver.steps(), units) +
            text,
        "snapshot");
    ++next_;
  }
  return s;
}

template <class G>
std::vector<std::string> Snapshots<G>::files() const {
  std::vector<std::string> names;
  for (std::int64_t k = 0; k < next_; ++k) names.push_back(file_name(k));
  return names;
}

template <class G>
void Snapshots<G>::declare_fields(mpm::FieldList& list) {
  list.group("analysis");
  list.add_attribute("next_snapshot", next_, "1");
}

template class Snapshots<mpm::PlaneStrain>;
template class Snapshots<mpm::Axisymmetric>;
template class Snapshots<mpm::ThreeD>;

}  // namespace oobleck::run
