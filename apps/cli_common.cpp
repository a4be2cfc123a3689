#include "cli_common.hpp"

#include <cstdlib>
#include <filesystem>
#include <sys/wait.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"

namespace oobleck::cli {

void ParamsOption::add_to(CLI::App* cmd) {
  auto* a =
      cmd->add_option("--preset", preset,
                      fmt::format("parameter set shipped in presets/: {}", fmt::join(rheology::preset_names(), ", ")));
  auto* b = cmd->add_option("--params", params, "parameter file (TOML, same format as presets/*.toml)");
  a->excludes(b);
  b->excludes(a);
}

rheology::Preset ParamsOption::load(const std::string& fallback_preset) const {
  if (!params.empty()) return rheology::load_params_file(params);
  if (!preset.empty()) return rheology::load_preset(preset);
  if (!fallback_preset.empty()) return rheology::load_preset(fallback_preset);
  throw InputError("one of --preset NAME or --params FILE is required");
}

std::string python() {
  if (const char* env = std::getenv("OOBLECK_PYTHON"); env != nullptr && *env != '\0') return env;
  return "/usr/bin/python3";
}

std::string tools_dir() { return std::string(OOBLECK_SOURCE_DIR) + "/tools"; }

namespace {
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}
}  // namespace

void run_tool(const std::string& script, const std::vector<std::string>& args) {
  std::string cmd = shell_quote(python()) + " " + shell_quote(tools_dir() + "/" + script);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    throw NumericalError(fmt::format("plotting failed (exit {}): {}", WEXITSTATUS(rc), cmd));
  }
}

void plot(const std::string& script, std::vector<std::string> args, const std::string& png) {
  const std::string tmp = png + ".tmp.png";
  args.push_back(tmp);
  try {
    run_tool(script, args);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
  std::filesystem::rename(tmp, png);
}

std::string num(double v) { return fmt::format("{:.17g}", v); }

}  // namespace oobleck::cli
