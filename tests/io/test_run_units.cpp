// Units in what `oobleck run` writes (docs/output.md, "Units"), checked against docs/output.md's
// own tables: every dataset of a frame has the `units` attribute the table states for its field
// (the mass per metre of depth in plane strain, per radian in axisymmetry), series.csv's first
// line names every column's unit (per radian in an axisymmetric run) and the C++ reader skips
// it, every checkpoint array states its units.
#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "io_test_util.hpp"
#include "oobleck/io/csv.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

using namespace oobleck;
using oobleck::test::TempDir;

namespace {

/// A verification scene stopped after 5 steps (with a checkpoint), on one thread.
void run_briefly(const std::string& scene, const std::string& out) {
  run::RunOptions o;
  o.out_dir = out;
  o.quiet = true;
  o.threads = 1;
  o.stop_after_steps = 5;
  run::run_scene(scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/verification/" + scene, {}), o);
}

/// docs/output.md's tables of frame fields: field -> its `units` column for this geometry (0 plane
/// strain, 1 axisymmetric, 2 3D; a cell of three units lists them in that order), for the bodies'
/// fields and the grid's.
std::pair<std::map<std::string, std::string>, std::map<std::string, std::string>> documented_units(int geometry) {
  std::ifstream in(std::string(OOBLECK_SOURCE_DIR) + "/docs/output.md");
  std::map<std::string, std::string> bodies, grid;
  const auto ticked = [](const std::string& cell) {  // the `...` parts of a cell
    std::vector<std::string> out;
    for (std::size_t a = cell.find('`'); a != std::string::npos; a = cell.find('`', cell.find('`', a + 1) + 1)) {
      const std::size_t b = cell.find('`', a + 1);
      if (b == std::string::npos) break;
      out.push_back(cell.substr(a + 1, b - a - 1));
    }
    return out;
  };
  const auto pick = [&](const std::string& cell) {
    const auto u = ticked(cell);
    return u.size() == 3 ? u[static_cast<std::size_t>(geometry)] : u.size() == 1 ? u[0] : std::string("?");
  };
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("| ")) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(2));
    for (std::string c; std::getline(ss, c, '|');) cells.push_back(c.substr(c.find_first_not_of(' ')));
    const auto is_ticked = [&](std::size_t k) { return k < cells.size() && cells[k].starts_with('`'); };
    if (cells.size() >= 5 && is_ticked(1) && is_ticked(3)) {
      bodies[ticked(cells[1]).front()] = pick(cells[3]);
    } else if (cells.size() >= 4 && is_ticked(0) && is_ticked(2)) {
      grid[ticked(cells[0]).front()] = pick(cells[2]);
    }
  }
  return {bodies, grid};
}

/// Every dataset of the first frame of `run` has the `units` attribute that docs/output.md states
/// for its field; the series' first line names every column's unit; every checkpoint array has
/// units, the bodies' masses those of the frames. Returns the series' units by column.
std::map<std::string, std::string> check_units(const std::string& run, int geometry) {
  const auto [bodies, grid] = documented_units(geometry);
  EXPECT_EQ(bodies.count("mass"), 1u);
  EXPECT_EQ(grid.count("porosity"), 1u);
  const std::string frame = run + "/frames/frame_000000.h5";
  const std::vector<std::string> datasets = oobleck::test::h5_datasets(frame);
  EXPECT_GE(datasets.size(), 9u);  // (a fluid alone: position, connectivity and 7 fields)
  for (const std::string& d : datasets) {
    std::string units;
    EXPECT_TRUE(oobleck::test::read_h5_text_attr(frame, d, "units", units)) << d;
    const std::string field = d.substr(d.rfind('/') + 1);
    const auto& table = d.starts_with("/grid/") ? grid : bodies;
    EXPECT_EQ(table.count(field), 1u) << d << ": not in docs/output.md's tables";
    if (table.count(field) == 1) {
      EXPECT_EQ(units, table.at(field)) << d;
    }
  }
  // series.csv: "# units: time=s, ..." then the header, the same names in the same order.
  std::ifstream in(run + "/series.csv");
  std::string first, header;
  std::getline(in, first);
  std::getline(in, header);
  EXPECT_TRUE(first.starts_with("# units: ")) << first;
  std::map<std::string, std::string> units;
  std::vector<std::string> named;
  std::stringstream ss(first.substr(std::min(first.size(), std::string("# units: ").size())));
  for (std::string item; std::getline(ss, item, ',');) {
    item = item.substr(item.find_first_not_of(' '));
    named.push_back(item.substr(0, item.find('=')));
    units[named.back()] = item.substr(item.find('=') + 1);
  }
  std::vector<std::string> columns;
  std::stringstream hs(header);
  for (std::string c; std::getline(hs, c, ',');) columns.push_back(c);
  EXPECT_EQ(named, columns);
  EXPECT_EQ(io::read_csv(run + "/series.csv").header, columns);  // the C++ reader skips the line
  // checkpoint.h5: every array has units; a body's point masses are the frames' mass.
  const std::string cp = run::checkpoint_path(run);
  for (const std::string& d : oobleck::test::h5_datasets(cp)) {
    std::string u;
    EXPECT_TRUE(oobleck::test::read_h5_text_attr(cp, d, "units", u)) << d;
    if (d == "/arrays/body0/mass") {
      EXPECT_EQ(u, bodies.at("mass"));
    }
  }
  return units;
}

}  // namespace

TEST(RunUnits, FramesSeriesAndCheckpointsStateTheirUnits) {
  TempDir d;
  run_briefly("settling.toml", d.file("plane"));
  const auto plane = check_units(d.file("plane"), 0);
  EXPECT_EQ(plane.at("time"), "s");
  EXPECT_EQ(plane.at("mass_grains"), "kg/m");  // per metre of depth
  EXPECT_EQ(plane.at("kinetic_energy_fluid"), "J/m");
  EXPECT_EQ(plane.at("max_speed_grains"), "m/s");
  run_briefly("couette_axisym.toml", d.file("axisym"));
  const auto axisym = check_units(d.file("axisym"), 1);
  std::size_t masses = 0;
  for (const auto& [column, unit] : axisym) {
    if (!column.starts_with("mass_")) continue;
    EXPECT_EQ(unit, "kg/rad") << column;  // per radian
    ++masses;
  }
  EXPECT_GE(masses, 1u);
  EXPECT_EQ(axisym.at("momentum_fluid_2"), "N s/rad");  // (v_theta: the third component)
}
