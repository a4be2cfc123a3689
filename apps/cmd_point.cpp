// `oobleck point ...`: placeholder until the material-point driver lands.
#include "cli_common.hpp"

namespace oobleck::cli {
void add_point_commands(CLI::App&) {}
}  // namespace oobleck::cli
