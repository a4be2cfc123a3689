#pragma once
// What `oobleck rheology flow-curve --data` shares with `rheology fit --kind curves` (cmd_fit.cpp):
// measured flow curves from --data FILE [--step NAME|INDEX] [--phi PHI] options.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "oobleck/io/csv.hpp"

namespace oobleck::cli {

struct FlowCurveData {
  io::CsvTable table;  ///< columns phi, shear_rate [1/s], shear_stress [Pa] (a CSV may hold more)
  std::string args;    ///< the exports' options, "--data F [--step 'S'] --phi P ..." ("" for one CSV)
};

/// The measured flow curves of `cmd`'s options --data (`data`, values `files`), --step (`step`,
/// values `steps`) and --phi (values `phi`): one CSV with a phi column (no --phi), or one --phi per
/// --data, each file a CSV without phi or an instrument export (io::read_rheometer), a --step after
/// a --data belonging to that file and one before the first --data to all. Prints a line per
/// export unless `quiet`. InputError for unequal counts, a missing column or a bad file.
FlowCurveData read_flow_curve_data(const CLI::App& cmd, const CLI::Option* data, const CLI::Option* step,
                                   const std::vector<std::string>& files, const std::vector<std::string>& steps,
                                   const std::vector<double>& phi, bool quiet);

}  // namespace oobleck::cli
