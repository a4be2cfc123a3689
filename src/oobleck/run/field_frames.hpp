#pragma once
// Sampled nodal fields as persistent fields (the annular and intrusion analyses): a list of
// frames under NAME is "NAME/time" (one time per frame), "NAME/values" (the frames' node values
// one after another, r fastest) and, for intrusion frames, "NAME/tip_z". Restored on the grid of
// the restarted run (the same scene, so the same grid).
#include <cstddef>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "oobleck/analysis/data.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/mpm/fields.hpp"
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

/// Declare `frames` (a member of the caller, which outlives the list) under `name`: their times,
/// `field_of(frame)` (a GridField2D& of `shape`; stored only when the first frame's is sampled)
/// and, where the frames have one, their tip_z_m. `owner`: these declarations create the frames
/// on restore; otherwise (a second field of the same frames) the frames are there already and
/// the stored count must match.
template <class Frame, class FieldOf>
void declare_field_frames(mpm::FieldList& list, const std::string& name, std::vector<Frame>& frames,
                          const analysis::GridField2D& shape, const char* unit, FieldOf field_of, bool owner = true) {
  auto sampled = [&frames, field_of] { return !frames.empty() && !field_of(frames.front()).values.empty(); };
  list.add_series(
      name + "/time", "s",
      [&frames, sampled] {
        std::vector<double> times;
        if (sampled())
          for (const auto& fr : frames) times.push_back(fr.time_s);
        return times;
      },
      [&frames, owner](const std::vector<double>& times) {
        if (owner) {
          frames.assign(times.size(), Frame{});
          for (std::size_t k = 0; k < times.size(); ++k) frames[k].time_s = times[k];
        } else if (times.size() != frames.size()) {
          throw InputError(fmt::format("{} frames where the first field has {}", times.size(), frames.size()));
        }
      });
  list.add_series(
      name + "/values", unit,
      [&frames, sampled, field_of] {
        std::vector<double> values;
        if (sampled())
          for (auto& fr : frames) {
            const analysis::GridField2D& f = field_of(fr);
            values.insert(values.end(), f.values.begin(), f.values.end());
          }
        return values;
      },
      [&frames, shape, field_of](const std::vector<double>& values) {
        const std::size_t n = shape.nx * shape.ny;
        if (values.size() != n * frames.size())
          throw InputError(
              fmt::format("{} values do not fill {} frames of this scene's {} nodes", values.size(), frames.size(), n));
        for (std::size_t k = 0; k < frames.size(); ++k) {
          analysis::GridField2D& f = field_of(frames[k]);
          f = shape;
          f.values.assign(values.begin() + static_cast<std::ptrdiff_t>(k * n),
                          values.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
        }
      });
  if constexpr (requires(Frame fr) { fr.tip_z_m; }) {
    list.add_series(
        name + "/tip_z", "m",
        [&frames, sampled] {
          std::vector<double> tips;
          if (sampled())
            for (const auto& fr : frames) tips.push_back(fr.tip_z_m);
          return tips;
        },
        [&frames](const std::vector<double>& tips) {
          for (std::size_t k = 0; k < frames.size() && k < tips.size(); ++k) frames[k].tip_z_m = tips[k];
        });
  }
}

}  // namespace oobleck::run
