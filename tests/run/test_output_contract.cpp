// The outputs' contract: the keys of summary.json (every key path, arrays of objects by the union
// of their elements' keys) and the columns of series.csv of the paper's four set-ups, each run a
// few steps on a coarse grid, equal to the lists recorded in tests/run/output_contract/. A change
// that renames, adds or drops a key or a column fails here and says which; when the change is
// meant, rerun the test with OOBLECK_RECORD_CONTRACT=1 to write the new lists (and say so in the
// commit).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_runner.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

namespace fs = std::filesystem;
using namespace oobleck;

namespace {

const std::string kSource = OOBLECK_SOURCE_DIR;

/// Every key path of a JSON value: "a.b" for objects, "a[].c" for the objects inside arrays.
void key_paths(const nlohmann::json& j, const std::string& prefix, std::set<std::string>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) {
      std::string path = prefix;
      if (!path.empty()) path += '.';
      path += k;
      out.insert(path);
      key_paths(v, path, out);
    }
  } else if (j.is_array()) {
    for (const auto& e : j) key_paths(e, prefix + "[]", out);
  }
}

/// The lines of the contract: "summary KEY" for each key path, then "series COLUMN" in order.
std::vector<std::string> contract_of(const fs::path& run_dir) {
  std::ifstream sf(run_dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(sf);
  std::set<std::string> keys;
  key_paths(summary, "", keys);
  std::vector<std::string> lines;
  lines.reserve(keys.size());
  for (const auto& k : keys) lines.push_back("summary " + k);
  std::ifstream cf(run_dir / "series.csv");
  std::string line;
  while (std::getline(cf, line) && !line.empty() && line[0] == '#') {
  }
  std::stringstream header(line);
  for (std::string col; std::getline(header, col, ',');) lines.push_back("series " + col);
  return lines;
}

void check_contract(const std::string& name, const std::string& scene, const std::vector<std::string>& sets) {
  clitest::TempDir d;
  run::RunOptions o;
  o.out_dir = d / name;
  o.quiet = true;
  o.threads = 1;
  run::run_scene(scene::load_scene(kSource + "/scenes/paper/" + scene, sets), o);
  const std::vector<std::string> got = contract_of(d / name);
  const fs::path file = fs::path(kSource) / "tests/run/output_contract" / (name + ".txt");
  if (std::getenv("OOBLECK_RECORD_CONTRACT") != nullptr) {
    std::ofstream f(file);
    for (const auto& l : got) f << l << "\n";
    GTEST_SKIP() << "recorded " << file;
  }
  std::ifstream f(file);
  ASSERT_TRUE(f) << "missing " << file;
  std::vector<std::string> want;
  for (std::string l; std::getline(f, l);)
    if (!l.empty()) want.push_back(l);
  const std::set<std::string> g(got.begin(), got.end()), w(want.begin(), want.end());
  for (const auto& l : w) EXPECT_TRUE(g.count(l)) << name << ": no longer written: " << l;
  for (const auto& l : g) EXPECT_TRUE(w.count(l)) << name << ": new, not in the contract: " << l;
  EXPECT_EQ(got, want) << name << ": the series columns' order differs";
}

}  // namespace

TEST(OutputContract, Intrusion) {
  check_contract("intrusion", "intrusion.toml",
                 {"duration=0.00005", "output.frame_interval=0.00005", "output.series_interval=0.00001"});
}

TEST(OutputContract, RodImpact) {
  check_contract(
      "rod_impact", "rod_impact.toml",
      {"cell_size=0.004", "duration=0.0002", "output.frame_interval=0.0002", "output.series_interval=0.00005"});
}

TEST(OutputContract, Wheel) {
  check_contract("wheel", "wheel.toml",
                 {"cells=[60,30]", "duration=0.0004", "output.frame_interval=0.0004", "output.series_interval=0.0002",
                  "analysis.sample_interval=0.0002"});
}

TEST(OutputContract, AnnularShear) {
  check_contract("annular_shear", "annular_shear.toml",
                 {"duration=0.0002", "output.frame_interval=0.0002", "output.series_interval=0.0001"});
}
