#pragma once
// What a run writes of the solver's state as it goes (docs/output.md): HDF5/XDMF frames of every
// body's points and the nodal porosity, and the rows of series.csv. Writing reads the state and
// changes nothing: the run loop samples its analyses itself.
#include <string>
#include <vector>

#include "oobleck/io/frames.hpp"
#include "oobleck/mpm/halo.hpp"
#include "oobleck/scene/build.hpp"

namespace oobleck::run {

/// f() on every rank while rank 0's bodies hold every rank's points (appended in rank order,
/// mpm/halo.hpp) and the other ranks' their own; afterwards each body holds only its own again.
/// For measurements that rank 0 makes over every point (the intrusion and wheel analyses). One
/// rank: f().
template <class G, class F>
void with_every_point_on_root(mpm::Solver<G>& solver, F&& f) {
  if (!solver.decomposition()) {
    f();
    return;
  }
  std::vector<std::int64_t> own(static_cast<std::size_t>(solver.body_count()));
  for (std::size_t b = 0; b < own.size(); ++b) own[b] = mpm::gather_points_to_root(solver.body(static_cast<int>(b)));
  f();
  for (std::size_t b = 0; b < own.size(); ++b) solver.body(static_cast<int>(b)).resize(own[b]);
}

/// Write one frame: per body its points' position, velocity, stress, pressure (fluid_pressure for
/// the fluid), mass and volume; the grains' f, phi, tau_bar, regime, gamma_dot_p; the fluid's phi
/// and J; and the nodal porosity on the physical nodes when there is a mixture. Decomposed runs:
/// called on every rank with its writer (io::Writers::every_rank), each writing its own points
/// and nodes.
template <class G>
void write_frame(io::FrameWriter& frames, const scene::BuiltScene<G>& scene);

/// Columns of a CSV file: each name with its unit beside it (for io::SeriesWriter).
struct Columns {
  std::vector<std::string> names, units;
  void add(std::string name, std::string unit) {
    names.push_back(std::move(name));
    units.push_back(std::move(unit));
  }
};

/// series.csv: time, step; per body its kinetic energy, momentum, mass and largest speed; per
/// [[body]] entry its centre of mass and contact force, and its motor's ω and torque. Units: SI,
/// amounts in the points' measure (in_measure: per metre of depth in plane strain, per radian in
/// axisymmetric runs).
template <class G>
Columns series_columns(const scene::BuiltScene<G>& scene);
/// (Decomposed runs: called on every rank; the row covers every rank's points.)
template <class G>
std::vector<double> series_row(const scene::BuiltScene<G>& scene);

}  // namespace oobleck::run
