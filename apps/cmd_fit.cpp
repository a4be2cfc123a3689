// `oobleck rheology fit`: placeholder until the Ceres fitting lands (owned by the fitting work).
#include "cli_common.hpp"
#include "oobleck/core/error.hpp"

namespace oobleck::cli {
void add_fit_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand("fit", "fit model parameters to rheometer data (Ceres)");
  cmd->callback([] { throw InputError("rheology fit is not implemented yet"); });
}
}  // namespace oobleck::cli
