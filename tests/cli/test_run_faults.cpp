// Faults during `oobleck run` (docs/reliability.md): a stop by SIGINT or SIGTERM leaves a
// checkpoint and a summary marked incomplete and continues bit for bit on --restart; SIGKILL at
// any moment leaves a checkpoint that restarts and an index that lists only complete frames; a
// file-size limit is a clear error naming the file with the previous checkpoint intact; a second
// run into a folder in use is refused.
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
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
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"

namespace fs = std::filesystem;
using clitest::Child;
using clitest::read_text;
using namespace oobleck;

namespace {

const std::string kSettling = std::string(OOBLECK_SOURCE_DIR) + "/scenes/verification/settling.toml";

/// Wait (up to 60 s) until `path` exists and holds at least `lines` lines besides its '#' lines
/// (the units line).
bool wait_for_lines(const std::string& path, int lines) {
  for (int k = 0; k < 6000; ++k) {
    std::ifstream in(path);
    int n = 0;
    for (std::string l; std::getline(in, l);)
      if (!l.starts_with('#')) ++n;
    if (n >= lines) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

nlohmann::json summary_of(const std::string& dir) { return nlohmann::json::parse(read_text(dir + "/summary.json")); }

/// Every array of two checkpoints equal bit for bit, and their clocks.
void expect_same_state(const io::Checkpoint& a, const io::Checkpoint& b) {
  EXPECT_EQ(a.step(), b.step());
  EXPECT_EQ(a.time(), b.time());
  ASSERT_EQ(a.names(), b.names());
  for (const auto& n : a.names()) {
    if (n == "granular/regime")
      EXPECT_EQ(a.bytes(n), b.bytes(n)) << n;
    else
      EXPECT_EQ(a.doubles(n), b.doubles(n)) << n;
  }
}

}  // namespace

TEST(RunFaults, SigintAndSigtermStopWithACheckpointAndRestartBitForBit) {
  clitest::TempDir d;
  const std::vector<std::string> scene = {kSettling, "--set", "time.duration=1.0", "--threads", "1", "--quiet"};
  for (int sig : {SIGINT, SIGTERM}) {
    const std::string out = d / ("stopped" + std::to_string(sig));
    std::vector<std::string> args = scene;
    args.insert(args.end(), {"--out", out, "--set", "output.series_interval=1e-4"});
    Child run("run", args, d / "log");
    ASSERT_TRUE(wait_for_lines(out + "/series.csv", 4));
    run.signal(sig);
    EXPECT_EQ(run.wait(), 128 + sig) << read_text(d / "log");
    const std::string log = read_text(d / "log");
    EXPECT_NE(log.find(sig == SIGINT ? "stopped by SIGINT" : "stopped by SIGTERM"), std::string::npos) << log;
    EXPECT_NE(log.find("--restart " + out), std::string::npos) << log;
    const auto s = summary_of(out);
    EXPECT_FALSE(s["complete"].get<bool>());
    EXPECT_EQ(s["stopped_by"], sig == SIGINT ? "SIGINT" : "SIGTERM");
    const io::Checkpoint cp = io::read_checkpoint(out + "/checkpoint.h5");
    EXPECT_EQ(cp.step(), s["steps"].get<std::int64_t>());

    // Continued to 40 steps past the stop, it holds the state of a run never stopped.
    const std::string until = std::to_string(cp.step() + 40);
    const auto r = clitest::run(fmt::format("run --restart {} --stop-after {} --threads 1 --quiet", out, until));
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string ref = d / ("ref" + std::to_string(sig));
    const auto u = clitest::run(fmt::format(
        "run {} --set time.duration=1.0 --set output.series_interval=1e-4 --threads 1 --quiet --out {} --stop-after {}",
        kSettling, ref, until));
    ASSERT_EQ(u.status, 0) << u.output;
    expect_same_state(io::read_checkpoint(ref + "/checkpoint.h5"), io::read_checkpoint(out + "/checkpoint.h5"));
  }
}

TEST(RunFaults, SigkillAtAnyMomentLeavesARestartableCheckpointAndCompleteFrames) {
  // Frames and checkpoints every few steps, so that kills land inside their writes too.
  clitest::TempDir d;
  if (clitest::shell("/usr/bin/python3 -c 'import xml.etree.ElementTree'").status != 0)
    GTEST_SKIP() << "/usr/bin/python3 not available for tools/check_xdmf.py";
  std::mt19937 rng(20261204);
  std::uniform_int_distribution<int> delay_ms(30, 900);
  int with_checkpoint = 0;
  for (int k = 0; k < 20; ++k) {
    const std::string out = d / ("killed" + std::to_string(k));
    Child run("run",
              {kSettling, "--set", "time.duration=1.0", "--set", "output.frame_interval=1e-4", "--checkpoint-every",
               "3", "--threads", "1", "--quiet", "--out", out},
              d / "log");
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    run.signal(SIGKILL);
    EXPECT_EQ(run.wait(), 128 + SIGKILL);
    if (fs::exists(out + "/frames.xmf")) {
      const auto check = clitest::shell("/usr/bin/python3 " + std::string(OOBLECK_SOURCE_DIR) +
                                        "/tools/check_xdmf.py --quiet '" + out + "/frames.xmf'");
      EXPECT_EQ(check.status, 0) << "kill " << k << ": " << check.output;
    }
    if (!fs::exists(out + "/checkpoint.h5")) continue;  // killed before its first checkpoint
    ++with_checkpoint;
    io::Checkpoint cp;
    ASSERT_NO_THROW(cp = io::read_checkpoint(out + "/checkpoint.h5")) << "kill " << k;
    const auto r = clitest::run("run --restart " + out + " --stop-after " + std::to_string(cp.step() + 3) +
                                " --threads 1 --quiet");
    EXPECT_EQ(r.status, 0) << "kill " << k << ": " << r.output;
    EXPECT_EQ(io::read_checkpoint(out + "/checkpoint.h5").step(), cp.step() + 3);
  }
  EXPECT_GE(with_checkpoint, 15);  // the kills fell inside the run, not only before it started
}

TEST(RunFaults, FileSizeLimitIsAClearErrorAndKeepsThePreviousCheckpoint) {
  clitest::TempDir d;
  const std::string out = d / "run";
  auto r =
      clitest::run("run " + kSettling + " --set time.duration=0.01 --stop-after 50 --threads 1 --quiet --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string before = read_text(out + "/checkpoint.h5");
  // The restart writes frames and a checkpoint of ~100 kB each; the limit is 16 kB per file.
  r = clitest::shell("ulimit -f 16; exec " + std::string(OOBLECK_CLI) + " run --restart " + out +
                     " --checkpoint-every 10 --threads 1 --quiet");
  EXPECT_EQ(r.status, 3) << "an error exit, not a crash: " << r.output;
  EXPECT_NE(r.output.find(out + "/"), std::string::npos) << "the message names the file: " << r.output;
  EXPECT_EQ(read_text(out + "/checkpoint.h5"), before);
  EXPECT_EQ(io::read_checkpoint(out + "/checkpoint.h5").step(), 50);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST(RunFaults, ASecondRunIntoAFolderInUseIsRefused) {
  clitest::TempDir d;
  const std::string out = d / "run";
  Child first("run",
              {kSettling, "--set", "time.duration=1.0", "--set", "output.series_interval=1e-4", "--threads", "1",
               "--quiet", "--out", out},
              d / "log");
  ASSERT_TRUE(wait_for_lines(out + "/series.csv", 3));
  const std::string series = read_text(out + "/series.csv");
  const auto second = clitest::run("run " + kSettling + " --set time.duration=0.01 --threads 1 --quiet --out " + out);
  EXPECT_EQ(second.status, 2) << second.output;
  EXPECT_NE(second.output.find("another oobleck run (pid " + std::to_string(first.pid()) + ")"), std::string::npos)
      << second.output;
  const auto restart = clitest::run("run --restart " + out + " --quiet");
  EXPECT_EQ(restart.status, 2) << restart.output;
  first.signal(SIGINT);
  EXPECT_EQ(first.wait(), 130);
  // The first run's output was not touched by the refused ones: its series only grew.
  EXPECT_EQ(read_text(out + "/series.csv").substr(0, series.size()), series);
  EXPECT_TRUE(summary_of(out)["stopped_by"] == "SIGINT");
}

// A numerical failure mid-run (the rod at time.cfl = 1 on 2.5 mm cells: grains thrown off the
// grid at step 461) stops with the diagnosis and keeps the last good checkpoint (step 460, one
// every 20 steps); `--restart DIR --set time.cfl=0.5` continues from it with half the time step,
// past the failure, and a later plain --restart keeps the new step. Only [time] may change.
TEST(RunFaults, NumericalFailureKeepsTheLastCheckpointAndARestartWithASmallerStepContinues) {
  clitest::TempDir d;
  const std::string out = d / "rod";
  const std::string rod = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/rod_impact.toml";
  auto r = clitest::run("run " + rod +
                        " --set time.cfl=1.0 --set cell_size=0.0025 --checkpoint-every 20 "
                        "--stop-after 600 --threads 1 --quiet --out " +
                        out);
  ASSERT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("numerical failure"), std::string::npos) << r.output;
  const auto at = r.output.find("at step ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const long failed_step = std::stol(r.output.substr(at + 8));
  const io::Checkpoint before = io::read_checkpoint(out + "/checkpoint.h5");
  EXPECT_EQ(before.step(), failed_step / 20 * 20) << "the last checkpoint before the failure";
  const double dt_before = before.real_attribute("dt");
  const double t_failed = before.time() + static_cast<double>(failed_step - before.step()) * dt_before;

  r = clitest::run("run --restart " + out + " --set grid.cell_size=0.001 --quiet");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("only [time] keys"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'grid.cell_size'"), std::string::npos) << r.output;
  EXPECT_EQ(io::read_checkpoint(out + "/checkpoint.h5").step(), before.step()) << "the refusal wrote nothing";

  const long until = before.step() + 140;
  r = clitest::run("run --restart " + out + " --set time.cfl=0.5 --stop-after " + std::to_string(until) +
                   " --threads 1 --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto s = summary_of(out);
  EXPECT_EQ(s["steps"].get<long>(), until);
  EXPECT_EQ(s["steps_this_run"].get<long>(), 140);
  EXPECT_NEAR(s["dt"].get<double>(), 0.5 * dt_before, 1e-15 * dt_before) << "dt = cfl x the stable step";
  EXPECT_NEAR(s["time"].get<double>(), before.time() + 140 * 0.5 * dt_before, 1e-12);
  EXPECT_GT(s["time"].get<double>(), t_failed) << "past the moment of the failure";
  EXPECT_EQ(s["restart_overrides"], nlohmann::json::array({"time.cfl=0.5"}));
  EXPECT_NE(read_text(out + "/scene.toml").find("cfl = 0.5"), std::string::npos);
  const io::Checkpoint after = io::read_checkpoint(out + "/checkpoint.h5");
  EXPECT_EQ(after.step(), until);
  EXPECT_EQ(after.real_attribute("dt"), s["dt"].get<double>());

  r = clitest::run("run --restart " + out + " --stop-after " + std::to_string(until + 10) + " --threads 1 --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(summary_of(out)["dt"].get<double>(), after.real_attribute("dt"));
  EXPECT_FALSE(summary_of(out).contains("restart_overrides"));
}
