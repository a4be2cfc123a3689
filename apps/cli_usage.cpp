#include "cli_usage.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::cli {
namespace {

/// One example per command, keyed by the command's path below `oobleck`. Each runs as written
/// from the repository root (tests/cli/test_cli_usage.cpp runs the short ones).
const std::map<std::string, std::string>& examples() {
  static const std::map<std::string, std::string> table = {
      {"", "oobleck rheology flow-curve --preset hermes2016 --phi 0.45 --phi 0.50 --out curves.csv --plot curves.png"},
      {"rheology", "oobleck rheology dst --preset hermes2016 --phi 0.45"},
      {"rheology flow-curve",
       "oobleck rheology flow-curve --preset hermes2016 --phi 0.45 --phi 0.50 --out curves.csv --plot curves.png"},
      {"rheology dst", "oobleck rheology dst --preset hermes2016 --phi 0.45 --json"},
      {"rheology structure", "oobleck rheology structure --preset singh2018a --out structure.csv --plot structure.png"},
      {"rheology volume-fraction",
       "oobleck rheology volume-fraction --mass-fraction 0.4 --rho-cs 1630 --rho-liquid 1000 --rho-water 1000"},
      {"rheology import",
       "oobleck rheology import tests/rheology/data/rheometer/trios_phi040.txt --step \"flow sweep\" --out flow.csv"},
      {"rheology fit",
       "oobleck rheology fit --kind low --data docs/fitting/min_viscosity.csv --preset dhaene1993 --out fitted.toml"},
      {"point", "oobleck point shear --preset hermes2016 --phi 0.50 --shear-rate 10 --duration 1 --out shear.csv"},
      {"point shear",
       "oobleck point shear --preset hermes2016 --phi 0.50 --shear-rate 10 --duration 1 --out shear.csv --plot "
       "shear.png"},
      {"point relax",
       "oobleck point relax --preset hermes2016 --phi 0.52 --shear-stress 100 --G 1e4 --G 1e5 --duration 1 --out "
       "relax.csv"},
      {"run", "oobleck run scenes/paper/intrusion.toml --set phi=0.49 --set v0=0.5 --out out/intrusion"},
      {"reproduce", "oobleck reproduce --quick --only S3 --out out/reproduce"},
      {"sweep",
       "oobleck sweep scenes/paper/intrusion.toml --vary phi=0.46:0.50:0.01 --vary v0=0.2,0.5 --jobs 2 --out "
       "out/s3_sweep --plot k_l_over_k_t"},
  };
  return table;
}

/// "rheology fit" for the command `oobleck rheology fit` ("" for oobleck itself).
std::string path_of(const CLI::App& cmd) {
  std::string path;
  for (const CLI::App* a = &cmd; a->get_parent() != nullptr; a = a->get_parent()) {
    if (!path.empty()) path.insert(0, 1, ' ');
    path.insert(0, a->get_name());
  }
  return path;
}

void add_examples_below(CLI::App& cmd) {
  if (auto it = examples().find(path_of(cmd)); it != examples().end()) cmd.footer("\nExample:\n  " + it->second);
  for (CLI::App* sub : cmd.get_subcommands([](CLI::App*) { return true; })) add_examples_below(*sub);
}

/// The deepest command the parser entered.
const CLI::App& deepest(const CLI::App& app) {
  const auto parsed = app.get_subcommands();
  return parsed.empty() ? app : deepest(*parsed.front());
}

std::vector<std::string> option_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::Option* opt : cmd.get_options()) {
    for (const auto& l : opt->get_lnames()) names.push_back("--" + l);
    for (const auto& s : opt->get_snames()) names.push_back("-" + s);
  }
  return names;
}

std::vector<std::string> command_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::App* sub : cmd.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  return names;
}

/// "unknown option '--thraeds' for 'oobleck run'; did you mean '--threads'?", or "" when the
/// parser left no word over.
std::string unknown_word_message(const CLI::App& cmd) {
  const auto left = cmd.remaining();
  if (left.empty()) return "";
  const std::string where = path_of(cmd).empty() ? "oobleck" : "oobleck " + path_of(cmd);
  // A command group's first word left over is a misspelt command. Otherwise an option is the
  // likelier typo: a misspelt option's value is then taken as a positional.
  auto it = std::find_if(left.begin(), left.end(), [](const std::string& w) { return w.size() > 1 && w[0] == '-'; });
  std::string word = it != left.end() && command_names(cmd).empty() ? *it : left.front();
  std::string kind;
  std::string suggestion;
  if (word[0] == '-') {
    word = word.substr(0, word.find('='));
    kind = "option";
    suggestion = closest_match(word, option_names(cmd));
  } else if (!command_names(cmd).empty()) {
    kind = "command";
    suggestion = closest_match(word, command_names(cmd));
  } else {
    kind = "argument";
  }
  std::string msg = fmt::format("unknown {} '{}' for '{}'", kind, word, where);
  if (!suggestion.empty()) msg += fmt::format("; did you mean '{}'?", suggestion);
  return msg;
}

}  // namespace

void add_examples(CLI::App& app) { add_examples_below(app); }

int report_usage_error(CLI::App& app, const CLI::ParseError& e) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
  // A command's own exit status, thrown from its callback (sweep: 3 when a run failed); it has
  // printed its message.
  if (dynamic_cast<const CLI::RuntimeError*>(&e) != nullptr) return e.get_exit_code();
  const CLI::App& cmd = deepest(app);
  std::string msg = unknown_word_message(cmd);
  if (msg.empty()) msg = e.what();
  const std::string path = path_of(cmd);
  std::fprintf(stderr, "oobleck: error: %s\nRun 'oobleck%s --help' for the options and an example.\n", msg.c_str(),
               path.empty() ? "" : (" " + path).c_str());
  return 1;
}

}  // namespace oobleck::cli
