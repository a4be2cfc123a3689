// `oobleck sweep` (issue 42, item 5): a grid of runs of the settling scene (a few ms of simulated
// time, well under a second each), their folders and sweep.csv; a rerun skips complete runs and
// continues one that holds a checkpoint; a failed run is a row and exit 3; SIGINT reaches the
// runs, which leave checkpoints; bad --vary specs and other bad input exit 2 with nothing written.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace fs = std::filesystem;
using clitest::Child;
using clitest::read_text;

namespace {

const std::string kSettling = std::string(OOBLECK_SOURCE_DIR) + "/scenes/verification/settling.toml";
/// Short runs: 2 ms of settling, on one thread each.
const std::string kShort =
    " --set analysis.average_from=0.001 --set output.frame_interval=0.001 --threads 1 --set time.duration=0.002";

/// A CSV file (RFC 4180 quoting) as rows of cells; row 0 is the header (leading '#' lines, the
/// units line, skipped).
std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::string text = read_text(path);
  while (text.starts_with('#')) text.erase(0, std::min(text.size(), text.find('\n') + 1));
  std::vector<std::vector<std::string>> rows(1);
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().push_back(cell);
      cell.clear();
    } else if (c == '\n') {
      rows.back().push_back(cell);
      cell.clear();
      rows.emplace_back();
    } else {
      cell += c;
    }
  }
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

/// Every scalar of a summary under its dotted key (arrays left out).
void flatten(const nlohmann::json& j, const std::string& key, std::map<std::string, nlohmann::json>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, key.empty() ? k : fmt::format("{}.{}", key, k), out);
  } else if (!j.is_array()) {
    out[key] = j;
  }
}

/// The cell of a sweep.csv row holds exactly the summary's value.
void expect_cell(const std::string& cell, const nlohmann::json& v, const std::string& what) {
  if (v.is_null()) {
    EXPECT_EQ(cell, "") << what;
  } else if (v.is_boolean()) {
    EXPECT_EQ(cell, v.get<bool>() ? "true" : "false") << what;
  } else if (v.is_number_integer()) {
    EXPECT_EQ(cell, std::to_string(v.get<long long>())) << what;
  } else if (v.is_number_float()) {
    ASSERT_FALSE(cell.empty()) << what;
    EXPECT_EQ(std::stod(cell), v.get<double>()) << what;  // exact: round-trip precision
  } else {
    EXPECT_EQ(cell, v.get<std::string>()) << what;
  }
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t k = 0; k < header.size(); ++k)
    if (header[k] == name) return k;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

}  // namespace

TEST(SweepCli, GridOfRunsTabulatesEverySummaryScalarAndARerunSkipsCompleteRuns) {
  clitest::TempDir d;
  const std::string out = d / "sweep";
  // 0.2 + 0.1 is 0.30000000000000004 in doubles: the range's values are rounded to its decimals.
  const std::string cmd =
      "sweep " + kSettling + " --vary phi=0.2:0.3:0.1 --vary d=1e-4,2e-4" + kShort + " --jobs 2 --out " + out;
  const bool matplotlib = clitest::shell("/usr/bin/python3 -c 'import matplotlib'").status == 0;
  auto r = clitest::run(cmd + " --plot settling_velocity");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> names = {"phi=0.2_d=1e-4", "phi=0.2_d=2e-4", "phi=0.3_d=1e-4", "phi=0.3_d=2e-4"};
  for (const auto& n : names) {
    EXPECT_TRUE(fs::exists(fmt::format("{}/{}/summary.json", out, n))) << n;
    EXPECT_NE(read_text(fmt::format("{}/{}/log.txt", out, n)).find("$ oobleck run "), std::string::npos) << n;
  }
  if (matplotlib) {
    EXPECT_TRUE(fs::exists(out + "/settling_velocity.png")) << r.output;
  }

  const auto check_table = [&](const std::string& message) {
    // The units line: d is material.granular.d, "# [m]" in settling.toml (phi has no unit comment),
    // then the summaries' columns with the units of their "units".
    const std::string text = read_text(out + "/sweep.csv");
    EXPECT_TRUE(text.starts_with("# units: d=m, ")) << text.substr(0, 200);
    const std::string units = text.substr(0, text.find('\n'));
    for (const char* u : {" dt=s,", " settling_velocity=m/s,", " parameters.d=m,", " parameters.rho_s=kg/m^3,"})
      EXPECT_NE(units.find(u), std::string::npos) << u << " in " << units;
    const auto rows = read_csv(out + "/sweep.csv");
    ASSERT_EQ(rows.size(), 5u);
    const auto& h = rows[0];
    ASSERT_GE(h.size(), 6u);
    EXPECT_EQ(h[0], "phi");
    EXPECT_EQ(h[1], "d");
    EXPECT_EQ(h[2], "run");
    EXPECT_EQ(h[h.size() - 2], "status");
    EXPECT_EQ(h.back(), "message");
    const double phis[] = {0.2, 0.2, 0.3, 0.3}, ds[] = {1e-4, 2e-4, 1e-4, 2e-4};
    for (std::size_t i = 1; i < rows.size(); ++i) {
      const auto& row = rows[i];
      ASSERT_EQ(row.size(), h.size()) << "row " << i;
      EXPECT_EQ(std::stod(row[0]), phis[i - 1]);
      EXPECT_EQ(row[0], phis[i - 1] == 0.2 ? "0.2" : "0.3");
      EXPECT_EQ(std::stod(row[1]), ds[i - 1]);
      EXPECT_EQ(row[2], names[i - 1]);
      EXPECT_EQ(row[h.size() - 2], "ok");
      EXPECT_EQ(row.back(), message);
      std::map<std::string, nlohmann::json> flat;
      auto summary = nlohmann::json::parse(read_text(out + "/" + row[2] + "/summary.json"));
      summary.erase("units");  // (its units: the first line's)
      flatten(summary, "", flat);
      for (const auto& [key, value] : flat) expect_cell(row[column(h, key)], value, row[2] + ": " + key);
      EXPECT_EQ(h.size(), flat.size() + 5) << "one column per scalar of the summaries";
      // What the runs were given: the varied values.
      EXPECT_EQ(std::stod(row[column(h, "parameters.d")]), ds[i - 1]);
    }
  };
  check_table("");

  // The same command again: every run is complete, none is run again.
  std::map<std::string, fs::file_time_type> mtimes;
  for (const auto& n : names) mtimes[n] = fs::last_write_time(fmt::format("{}/{}/summary.json", out, n));
  r = clitest::run(cmd);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("4 complete"), std::string::npos) << r.output;
  for (const auto& n : names) EXPECT_EQ(fs::last_write_time(fmt::format("{}/{}/summary.json", out, n)), mtimes[n]) << n;
  check_table("skipped: complete summary.json");
}

TEST(SweepCli, AFailedRunIsARowAndTheSweepExitsWith3) {
  clitest::TempDir d;
  const std::string out = d / "sweep";
  const auto r = clitest::run("sweep " + kSettling +
                              " --vary time.duration=0.002,-0.001 --set analysis.average_from=0.001 "
                              "--set output.frame_interval=0.001 --threads 1 --out " +
                              out);
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("1 of 2 run(s) failed"), std::string::npos) << r.output;
  const auto rows = read_csv(out + "/sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  const auto& h = rows[0];
  EXPECT_EQ(h[0], "time.duration");
  const std::size_t status = column(h, "status"), message = column(h, "message");
  EXPECT_EQ(rows[1][1], "time.duration=0.002");
  EXPECT_EQ(rows[1][status], "ok");
  EXPECT_EQ(rows[2][1], "time.duration=-0.001");
  EXPECT_EQ(rows[2][status], "failed");
  EXPECT_NE(rows[2][message].find("exit 2"), std::string::npos) << rows[2][message];
  EXPECT_NE(rows[2][message].find("duration"), std::string::npos) << rows[2][message];
  EXPECT_EQ(rows[2][column(h, "steps")], "") << "a failed run has no summary values";
  EXPECT_NE(rows[1][column(h, "steps")], "");
}

TEST(SweepCli, ARunWithACheckpointIsContinuedAndSigintStopsTheRunsWithCheckpoints) {
  clitest::TempDir d;
  const std::string out = d / "sweep";
  // A run stopped after 20 steps (checkpoint, summary "complete": false) in the sweep's folder.
  const std::string sets = " --set analysis.average_from=0.001 --set output.frame_interval=0.001 --threads 1";
  auto r = clitest::run("run " + kSettling + sets +
                        " --set time.duration=0.002 --set phi=0.2 --stop-after 20 --quiet --out " + out + "/phi=0.2");
  ASSERT_EQ(r.status, 0) << r.output;
  r = clitest::run("sweep " + kSettling + " --vary phi=0.2 --set time.duration=0.002" + sets + " --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("1 to continue"), std::string::npos) << r.output;
  EXPECT_NE(read_text(out + "/phi=0.2/log.txt").find("--restart"), std::string::npos);
  auto s = nlohmann::json::parse(read_text(out + "/phi=0.2/summary.json"));
  EXPECT_TRUE(s["complete"].get<bool>());
  auto rows = read_csv(out + "/sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].back(), "continued from its checkpoint");

  // SIGINT to the sweep: forwarded to the running run, which stops with a checkpoint; no new
  // run starts; sweep.csv says so; exit 130.
  const std::string out2 = d / "stopped";
  Child sweep("sweep",
              {kSettling, "--vary", "phi=0.2,0.3", "--set", "time.duration=1.0", "--set", "output.series_interval=1e-4",
               "--threads", "1", "--out", out2},
              d / "log");
  const std::string series = out2 + "/phi=0.2/series.csv";
  for (int k = 0; k < 6000 && !fs::exists(series); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(fs::exists(series)) << read_text(d / "log");
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  sweep.signal(SIGINT);
  EXPECT_EQ(sweep.wait(), 130) << read_text(d / "log");
  EXPECT_TRUE(fs::exists(out2 + "/phi=0.2/checkpoint.h5")) << read_text(out2 + "/phi=0.2/log.txt");
  EXPECT_FALSE(fs::exists(out2 + "/phi=0.3"));
  rows = read_csv(out2 + "/sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  const std::size_t status = column(rows[0], "status");
  EXPECT_EQ(rows[1][status], "stopped");
  EXPECT_EQ(rows[2][status], "not started");
}

TEST(SweepCli, BadInputExitsWith2AndWritesNothing) {
  clitest::TempDir d;
  const std::string out = d / "sweep";
  struct Case {
    std::string args, needle;
  };
  const std::vector<Case> cases = {
      {"--vary phi=", "--vary phi=: no values"},
      {"--vary phi", "expected KEY=SPEC"},
      {"--vary =0.1", "the key is empty"},
      {"--vary phi=0.1,,0.2", "value 2 is empty"},
      {"--vary phi=0.1,0.2,", "value 3 is empty"},
      {"--vary phi=0.1,0.1", "given twice"},
      {"--vary phi=0.1:0.2:0", "step 0 must be > 0"},
      {"--vary phi=0.1:0.2:-0.1", "step -0.1 must be > 0"},
      {"--vary phi=a:0.2:0.1", "range start 'a' is not a finite number"},
      {"--vary phi=0.1:b:0.1", "range stop 'b' is not a finite number"},
      {"--vary phi=0.1:0.2", "start:stop:step"},
      {"--vary phi=0.3:0.2:0.1", "below start"},
      {"--vary phi=0.1 --vary phi=0.2", "varied twice"},
      {"--vary phi=0.1 --set phi=0.2", "also given with --vary"},
      {"", "--vary KEY=SPEC is required"},
      {"--vary phi=0.1 --jobs 0", "--jobs 0: must be >= 1"},
      {"--vary phi=0.1 --set grid.no_such_key=1", "no_such_key"},
      {"--vary no_such_alias=1", "no_such_alias"},
  };
  for (const auto& c : cases) {
    const auto r = clitest::run(fmt::format("sweep {} {} --out {}", kSettling, c.args, out));
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.needle), std::string::npos) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  const auto r = clitest::run("sweep " + d / "missing.toml" + " --vary phi=0.1 --out " + out);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("missing.toml: no such file"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}
