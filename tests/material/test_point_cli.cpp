// `oobleck point` CLI: bad input is an InputError (exit 2) naming the option and rule, with no
// output written; a short run writes the documented CSV header.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

namespace {

struct CliRun {
  int status;
  std::string output;
};

CliRun run(const std::string& args) {
  // One log per test process: ctest runs tests of this file in parallel processes.
  const std::string log =
      std::filesystem::temp_directory_path() / ("oobleck_point_cli_" + std::to_string(::getpid()) + ".log");
  const std::string cmd = std::string(OOBLECK_CLI) + " " + args + " > " + log + " 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream in(log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return {WEXITSTATUS(rc), text};
}

std::string tmp(const std::string& name) {
  return std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
}

}  // namespace

TEST(PointCli, BadInputExitsTwoWithoutOutput) {
  const std::string out = tmp("oobleck_point_bad.csv");
  std::filesystem::remove(out);
  const struct {
    std::string args, expect;
  } cases[] = {
      {"--phi 1.2 --shear-rate 1 --duration 1", "--phi"},
      {"--phi 0.4 --shear-rate -1 --duration 1", "--shear-rate"},
      {"--phi 0.4 --duration 1", "--shear-rate"},
      {"--phi 0.4 --shear-rate 1 --duration 0", "--duration"},
      {"--phi 0.4 --shear-rate 1 --duration 1 --dt 2", "--dt"},
      {"--phi 0.4 --shear-rate 1 --duration 1 --G -5", "--G"},
      {"--phi 0.4 --shear-rate 1 --duration 1 --f0 1.5", "--f0"},
      {"--phi 0.4 --shear-rate 1 --duration 1 --mu2 0.1", "--mu2"},
  };
  for (const auto& c : cases) {
    const CliRun r = run("point shear --preset hermes2016 " + c.args + " --out " + out);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
  const CliRun r = run("point relax --preset hermes2016 --phi 0.6 --shear-rate 1 --duration 1 --out " + out);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(PointCli, ShearAndRelaxWriteCsv) {
  const std::string out = tmp("oobleck_point_ok.csv");
  CliRun r = run(
      "point shear --preset hermes2016 --phi 0.44 --shear-rate 10 --duration 0.5 --dt 1e-3 --samples 20 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  {
    std::ifstream in(out);
    std::string units, header;
    std::getline(in, units);  // "# units: time=s, ..." (the text column regime left out)
    std::getline(in, header);
    EXPECT_EQ(units.rfind("# units: time=s, strain=1, shear_rate=1/s, shear_stress=Pa, ", 0), 0u) << units;
    EXPECT_EQ(
        header.rfind(
            "time,strain,shear_rate,shear_stress,granular_shear_stress,granular_pressure,sigma_xy,f,phi,regime", 0),
        0u)
        << header;
  }
  r =
      run("point relax --preset hermes2016 --phi 0.52 --shear-rate 0.05 --G 1e4 --G 1e5 --duration 0.05 --samples 20 "
          "--out " +
          out);
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(out);
  std::string units, header;
  std::getline(in, units);
  std::getline(in, header);
  EXPECT_EQ(units,
            "# units: case=1, G=Pa, K_0=1, time=s, granular_shear_stress=Pa, granular_pressure=Pa, f=1, "
            "gamma_dot_p=1/s, ode_granular_shear_stress=Pa, ode_f=1");
  EXPECT_EQ(
      header,
      "case,G,K_0,time,granular_shear_stress,granular_pressure,f,gamma_dot_p,regime,ode_granular_shear_stress,ode_f");
}
