#pragma once
// Checkpoint form of sampled nodal fields (the annular and intrusion analyses): under NAME,
// "NAME/time" (one time per frame), "NAME/values" (the frames' node values one after another,
// r fastest) and, for intrusion frames, "NAME/tip_z". Restored on the grid of the restarted
// run (the same scene, so the same grid).
#include <string>
#include <vector>

#include <fmt/format.h>

#include "oobleck/analysis/annular.hpp"
#include "oobleck/analysis/data.hpp"
#include "oobleck/analysis/fronts.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/grid.hpp"

namespace oobleck::run {

/// An empty field on the physical nodes of a 2D grid (the shape the sampled fields have).
inline analysis::GridField2D node_field_shape(const mpm::Grid<2>& grid) {
  analysis::GridField2D shape;
  shape.origin_x = grid.origin_m[0];
  shape.origin_y = grid.origin_m[1];
  shape.h = grid.h_m;
  shape.nx = static_cast<std::size_t>(grid.periodic[0] ? grid.cells[0] : grid.cells[0] + 1);
  shape.ny = static_cast<std::size_t>(grid.periodic[1] ? grid.cells[1] : grid.cells[1] + 1);
  return shape;
}

/// Store frames[k].time_s, field_of(frames[k]) and (where the frames have one) their tip_z_m.
template <class Frame, class FieldOf>
void save_field_frames(io::CheckpointWriter& cp, const std::string& name, const std::vector<Frame>& frames,
                       FieldOf field_of) {
  if (frames.empty()) return;
  std::vector<double> times, values, tips;
  for (const auto& fr : frames) {
    times.push_back(fr.time_s);
    const analysis::GridField2D& f = field_of(fr);
    values.insert(values.end(), f.values.begin(), f.values.end());
    if constexpr (requires { fr.tip_z_m; }) tips.push_back(fr.tip_z_m);
  }
  cp.array(name + "/time", times);
  cp.array(name + "/values", values);
  if (!tips.empty()) cp.array(name + "/tip_z", tips);
}

/// Append make(time, field of `shape` with the stored values, k) for every stored frame k.
template <class Frame, class Make>
void restore_field_frames(const io::Checkpoint& cp, const std::string& name, const analysis::GridField2D& shape,
                          std::vector<Frame>& frames, Make make) {
  if (!cp.has(name + "/time")) return;
  const auto& times = cp.doubles(name + "/time");
  const auto& values = cp.doubles(name + "/values");
  const std::size_t n = shape.nx * shape.ny;
  if (values.size() != n * times.size())
    throw InputError(fmt::format("{}: '{}' does not match this scene's grid", cp.file(), name));
  for (std::size_t k = 0; k < times.size(); ++k) {
    analysis::GridField2D f = shape;
    f.values.assign(values.begin() + static_cast<std::ptrdiff_t>(k * n),
                    values.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
    frames.push_back(make(times[k], std::move(f), k));
  }
}

inline void save_intrusion_frames(io::CheckpointWriter& cp, const std::string& name,
                                  const std::vector<analysis::IntrusionFrame>& frames) {
  save_field_frames(cp, name, frames,
                    [](const analysis::IntrusionFrame& f) -> const analysis::GridField2D& { return f.field; });
}

inline void restore_intrusion_frames(const io::Checkpoint& cp, const std::string& name,
                                     const analysis::GridField2D& shape,
                                     std::vector<analysis::IntrusionFrame>& frames) {
  const std::vector<double> tips = cp.has(name + "/tip_z") ? cp.doubles(name + "/tip_z") : std::vector<double>{};
  restore_field_frames(cp, name, shape, frames, [&](double t, analysis::GridField2D f, std::size_t k) {
    analysis::IntrusionFrame fr;
    fr.time_s = t;
    fr.tip_z_m = k < tips.size() ? tips[k] : 0.0;
    fr.field = std::move(f);
    return fr;
  });
}

}  // namespace oobleck::run
