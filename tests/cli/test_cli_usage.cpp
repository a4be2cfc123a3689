// The CLI's habits (README "Exit status", apps/cli_usage.hpp): usage errors exit 1 with
// `oobleck: error:` and the unknown word quoted, "did you mean" for a near miss; every command's
// --help ends with an example that runs; --preset lists the presets; run --list-keys.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_runner.hpp"

using clitest::run;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// The subcommand names listed under "Subcommands:" in a --help text.
std::vector<std::string> subcommands_in_help(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Subcommands:", 0) == 0) {
      inside = true;
      continue;
    }
    if (inside && line.rfind("  ", 0) == 0 && line.size() > 2 && line[2] != ' ') {
      names.push_back(line.substr(2, line.find(' ', 2) - 2));
    } else if (inside && !line.empty()) {
      inside = false;
    }
  }
  return names;
}

/// Every command path below oobleck ("", "rheology", "rheology fit", ...).
void collect_commands(const std::string& path, std::vector<std::string>& out) {
  out.push_back(path);
  const auto r = run(path + " --help");
  for (const auto& sub : subcommands_in_help(r.output)) {
    std::string below = path;
    if (!below.empty()) below += ' ';
    below += sub;
    collect_commands(below, out);
  }
}

}  // namespace

TEST(CliUsage, UnknownCommandExitsOneAndSuggestsTheNearest) {
  const auto r = run("rnu scenes/paper/intrusion.toml");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "oobleck: error: unknown command 'rnu' for 'oobleck'; did you mean 'run'?"))
      << r.output;
  const auto sub = run("rheology flow-curv --phi 0.4");
  EXPECT_EQ(sub.status, 1);
  EXPECT_TRUE(contains(sub.output, "unknown command 'flow-curv' for 'oobleck rheology'; did you mean 'flow-curve'?"))
      << sub.output;
  const auto far = run("rheology zzzzzz");
  EXPECT_EQ(far.status, 1);
  EXPECT_TRUE(contains(far.output, "unknown command 'zzzzzz'")) << far.output;
  EXPECT_FALSE(contains(far.output, "did you mean")) << far.output;
}

TEST(CliUsage, UnknownOptionExitsOneAndSuggestsTheNearest) {
  const auto r = run("run --thraeds 2 scenes/paper/intrusion.toml");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "unknown option '--thraeds' for 'oobleck run'; did you mean '--threads'?"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "Run 'oobleck run --help'")) << r.output;
  const auto eq = run("point relax --phi 0.5 --durration=1");
  EXPECT_EQ(eq.status, 1);
  EXPECT_TRUE(contains(eq.output, "unknown option '--durration' for 'oobleck point relax'; did you mean '--duration'?"))
      << eq.output;
}

TEST(CliUsage, EveryUsageErrorExitsOne) {
  for (const char* args : {"", "rheology", "rheology dst --phi", "rheology dst --phi x --preset hermes2016",
                           "point shear --preset hermes2016 --phi 0.5", "sweep"}) {
    const auto r = run(args);
    EXPECT_EQ(r.status, 1) << "oobleck " << args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "oobleck: error: ")) << "oobleck " << args << "\n" << r.output;
  }
  EXPECT_EQ(run("--help").status, 0);
  EXPECT_EQ(run("--version").status, 0);
}

TEST(CliUsage, EveryCommandsHelpEndsWithAnExampleOfThatCommand) {
  std::vector<std::string> commands;
  collect_commands("", commands);
  EXPECT_GE(commands.size(), 14U);  // oobleck, 2 groups, their 8 commands, run, reproduce, sweep
  for (const auto& c : commands) {
    const auto r = run(c + " --help");
    ASSERT_EQ(r.status, 0) << c;
    const auto at = r.output.rfind("\nExample:\n  oobleck ");
    ASSERT_NE(at, std::string::npos) << "'oobleck " << c << " --help' has no example:\n" << r.output;
    const std::string example = r.output.substr(at + 12);
    EXPECT_EQ(example.find('\n'), example.size() - 1) << "the example is not the help's last line: " << c;
    if (!c.empty() && c.find(' ') != std::string::npos) {
      EXPECT_EQ(example.rfind("oobleck " + c + " ", 0), 0U) << "example of '" << c << "': " << example;
    }
  }
}

TEST(CliUsage, TheShortExamplesRun) {
  // Run from a scratch folder, with the repository's files at their absolute paths.
  std::vector<std::string> commands;
  collect_commands("", commands);
  clitest::TempDir d;
  int ran = 0;
  for (const auto& c : commands) {
    if (c.empty() || c == "run" || c == "reproduce" || c == "sweep") continue;  // scene runs: minutes
    const auto help = run(c + " --help").output;
    std::string example = help.substr(help.rfind("\nExample:\n  oobleck ") + 20);
    example = example.substr(0, example.find('\n'));
    example = std::regex_replace(example, std::regex(" (docs|scenes|tests)/"),
                                 std::string(" ") + OOBLECK_SOURCE_DIR + "/$1/");
    const auto r = clitest::shell("cd " + d.path.string() + " && " + std::string(OOBLECK_CLI) + " " + example);
    EXPECT_EQ(r.status, 0) << "oobleck " << example << "\n" << r.output;
    ++ran;
  }
  EXPECT_GE(ran, 10);
}

TEST(CliUsage, PresetOptionListsThePresets) {
  const auto r = run("rheology dst --help");
  for (const char* name : {"hermes2016", "singh2018a", "dhaene1993", "fall2015"})
    EXPECT_TRUE(contains(r.output, name)) << name << "\n" << r.output;
}

TEST(CliUsage, ListKeysPrintsAliasesAndKeysWithTheirComments) {
  clitest::TempDir d;
  const std::string scene = d / "s.toml";
  std::ofstream(scene) << "[scene]\nname = \"t\"\n[aliases]\nphi = \"region.0.phi\"  # [-] bed volume fraction\n"
                          "depth = \"region.0.max\"\nspeed = \"body.0.speed\"  # [m/s] not in the file\n"
                          "[grid]\ncell_size = 0.002   # [m] coarse\n[[region]]\nphi = 0.47\nmax = [0.05, 0.03]\n";
  const auto r = run("run " + scene + " --list-keys");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(\n  phi +0\.47 +region\.0\.phi +\[-\] bed volume fraction\n)")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(\n  depth +\[0\.05, 0\.03\] +region\.0\.max +\n)")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(\n  speed +\(default\) +body\.0\.speed +\[m/s\])")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(\n  grid\.cell_size = 0\.002 +# \[m\] coarse\n)"))) << r.output;
  EXPECT_TRUE(contains(r.output, "\n  region.0.phi = 0.47\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "\n  scene.name = \"t\"\n")) << r.output;
  EXPECT_FALSE(contains(r.output, "aliases.")) << r.output;
  EXPECT_FALSE(std::filesystem::exists("out/t")) << "--list-keys wrote a run folder";
}
