// oobleck: simulator for dense, fine-particle suspensions (Baumgarten & Kamrin 2019).
// Exit status: 0 success, 1 usage error, 2 bad input (file/key/value named), 3 numerical failure
// or an output that could not be written, 128 + N a run stopped by signal N (130: SIGINT, 143:
// SIGTERM) after writing its checkpoint.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_common.hpp"
#include "cli_usage.hpp"
#include "oobleck/core/build_info.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/hdf5_state.hpp"
#include "oobleck/run/stop.hpp"

namespace {

/// "oobleck" or, in a run of several MPI ranks, "oobleck (rank r)".
std::string who() {
  return oobleck::comm::size() > 1 ? fmt::format("oobleck (rank {})", oobleck::comm::rank()) : "oobleck";
}

int run_cli(int argc, char** argv) {
  CLI::App app{"oobleck — dense suspension simulator (Baumgarten–Kamrin 2019 model)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", oobleck::version_string());
  oobleck::cli::add_rheology_commands(app);
  oobleck::cli::add_point_commands(app);
  oobleck::cli::add_run_command(app);
  oobleck::cli::add_reproduce_command(app);
  oobleck::cli::add_sweep_command(app);
  oobleck::cli::add_examples(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return oobleck::cli::report_usage_error(app, e);
  } catch (const oobleck::run::Stopped& e) {
    fmt::print(stderr, "{}: {}\n", who(), e.what());
    return 128 + e.signal();
  } catch (const oobleck::InputError& e) {
    fmt::print(stderr, "{}: error: {}\n", who(), e.what());
    return 2;
  } catch (const oobleck::NumericalError& e) {
    fmt::print(stderr, "{}: numerical failure: {}\n", who(), e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "{}: error: {}\n", who(), e.what());
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A write past a file-size limit (ulimit -f) fails with EFBIG and is reported with the file's
  // name, instead of the signal ending the process mid-write.
  std::signal(SIGXFSZ, SIG_IGN);
  oobleck::comm::init(argc, argv);  // MPI only under mpirun (core/comm.hpp)
  int status = 3;
  try {
    status = run_cli(argc, argv);
  } catch (const std::exception& e) {
    // Reporting an error failed in turn (fmt::print throws when stderr is closed or full), or the
    // CLI could not be set up: an error exit with status 3 (an output that could not be written),
    // not std::terminate's abort. The message is best effort (std::fprintf does not throw).
    std::fprintf(stderr, "oobleck: error: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "oobleck: error: unknown exception\n");
  }
  // Several ranks: one that fails stops the others (they may be waiting for it in an exchange).
  if (status != 0 && oobleck::comm::size() > 1) {
    std::fflush(nullptr);
    oobleck::comm::abort(status);
  }
  oobleck::comm::finalize();
  if (oobleck::io::hdf5_file_close_failed()) {  // io/hdf5_state.hpp: skip HDF5's shutdown
    std::fflush(nullptr);
    std::_Exit(status);
  }
  return status;
}
