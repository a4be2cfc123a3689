#pragma once
// The CLI's habits (README "Exit status"): usage errors exit 1 with `oobleck: error:`, quote the
// unknown word and suggest the nearest command or option; every command's --help ends with one
// example. The nearest name is core/error.hpp's closest_match.
#include <string>

#include <CLI/CLI.hpp>

namespace oobleck::cli {

/// Sets each command's help footer to its example (call after every command has been added).
void add_examples(CLI::App& app);

/// Reports a parse error of `app` on stderr and returns the exit status: 0 for --help and
/// --version (printed as CLI11 does), a command's own status thrown as CLI::RuntimeError(status)
/// (printed nothing more), 1 for every usage error.
int report_usage_error(CLI::App& app, const CLI::ParseError& e);

}  // namespace oobleck::cli
