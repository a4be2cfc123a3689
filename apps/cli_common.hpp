#pragma once
// Pieces shared by the oobleck subcommands: parameter selection (--preset/--params), plotting
// through matplotlib scripts in tools/, and number formatting for CSV/JSON.
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>

#include "oobleck/rheology/params.hpp"

namespace oobleck::cli {

/// Adds --preset NAME and --params FILE (mutually exclusive) to `cmd`.
struct ParamsOption {
  std::string preset;
  std::string params;
  void add_to(CLI::App* cmd);
  /// Loads and validates the chosen set. Falls back to `fallback_preset` when neither is given
  /// and fallback_preset is not empty.
  rheology::Preset load(const std::string& fallback_preset = "") const;
};

/// Python interpreter with matplotlib: $OOBLECK_PYTHON, else /usr/bin/python3.
std::string python();
/// Folder of the plotting scripts.
std::string tools_dir();
/// Run tools/<script> with arguments; throws NumericalError if the script fails.
void run_tool(const std::string& script, const std::vector<std::string>& args);

/// Run tools/<script> with `args` + a temporary PNG path, renamed to `png` only on success
/// (no partial figure on failure).
void plot(const std::string& script, std::vector<std::string> args, const std::string& png);

/// Shortest round-trip representation of a double ("17 significant digits").
std::string num(double v);

/// Temporary files of a command (the plot scripts' inputs), removed when it goes out of scope,
/// whatever the exit path.
struct TempFiles {
  std::vector<std::string> files;
  TempFiles() = default;
  TempFiles(const TempFiles&) = delete;
  TempFiles& operator=(const TempFiles&) = delete;
  ~TempFiles() {
    std::error_code ec;
    for (const auto& f : files) std::filesystem::remove(f, ec);
  }
};

/// Register subcommands (one file per command group).
void add_rheology_commands(CLI::App& app);
void add_fit_command(CLI::App& rheology);
void add_point_commands(CLI::App& app);
void add_run_command(CLI::App& app);
void add_reproduce_command(CLI::App& app);
void add_sweep_command(CLI::App& app);

}  // namespace oobleck::cli
