// The `oobleck rheology` CLI contract: file formats, JSON shape, and bad input -> clear message,
// non-zero exit, no output file created or overwritten.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace fs = std::filesystem;
using clitest::run;

using clitest::read_text;

TEST(RheologyCli, FlowCurveCsvHasContractColumnsAndOrderedRows) {
  clitest::TempDir d;
  const auto r = run("rheology flow-curve --preset hermes2016 --phi 0.40 --phi 0.47 --points 50 --out " + d / "fc.csv");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(d / "fc.csv");
  std::string header;
  std::getline(in, header);
  for (const char* col :
       {"phi", "f", "shear_rate", "shear_stress", "granular_pressure", "granular_shear_stress", "viscosity"}) {
    EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos) << col;
  }
  int rows = 0;
  double last_phi = -1, last_f = -1;
  for (std::string line; std::getline(in, line); ++rows) {
    const double phi = std::stod(line.substr(0, line.find(',')));
    const double f = std::stod(line.substr(line.find(',') + 1));
    if (phi == last_phi) {
      EXPECT_GT(f, last_f);
    }
    last_phi = phi;
    last_f = f;
  }
  EXPECT_EQ(rows, 100);
}

TEST(RheologyCli, DstJsonShape) {
  auto r = run("rheology dst --preset hermes2016 --phi 0.45 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  auto j = nlohmann::json::parse(r.output);
  EXPECT_DOUBLE_EQ(j["phi"].get<double>(), 0.45);
  EXPECT_GT(j["shear_rate_dst"].get<double>(), 0.0);
  // The fastest steady shear is never below the DST asymptote.
  EXPECT_GE(j["max_shear_rate"].get<double>(), j["shear_rate_dst"].get<double>() * (1 - 1e-12));
  r = run("rheology dst --preset hermes2016 --phi 0.40 --json");  // CST: DST does not apply
  ASSERT_EQ(r.status, 0) << r.output;
  j = nlohmann::json::parse(r.output);
  EXPECT_TRUE(j["shear_rate_dst"].is_null());
  EXPECT_TRUE(j["max_shear_rate"].is_null());  // CST: any rate flows steadily
  EXPECT_TRUE(j["max_shear_rate_stress"].is_null());
}

TEST(RheologyCli, VolumeFractionAndStructure) {
  auto r =
      run("rheology volume-fraction --mass-fraction 0.4 --rho-cs 1000 --rho-liquid 1000 --rho-water 1000 "
          "--lambda 0 --beta 0 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NEAR(nlohmann::json::parse(r.output)["phi"].get<double>(), 0.4, 1e-14);
  clitest::TempDir d;
  r = run("rheology structure --preset singh2018a --points 20 --out " + d / "f.csv");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(read_text(d / "f.csv").rfind("stress,f_model,f_wyart_cates,f_singh\n", 0), 0u);
}

struct BadCase {
  std::string args;     // arguments; {OUT} is the output path
  std::string message;  // substring the error must contain
};

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ClearMessageNonZeroExitNoOutput) {
  clitest::TempDir d;
  const std::string out = d / "out.csv";
  // A bad file used by several cases.
  std::ofstream(d / "bad.toml")
      << "[steady]\nphi_c = 0.6\nphi_j = 0.5\na_0 = 1\na_inf = 1\ntau_star = 1\neta_0 = 1\nmu_c = 1\n";
  std::ofstream(d / "neg.toml")
      << "[steady]\nphi_c = 0.4\nphi_j = 0.5\na_0 = 1\na_inf = 1\ntau_star = 1\neta_0 = -1\nmu_c = 1\n";
  std::ofstream(d / "miss.toml") << "[steady]\nphi_c = 0.4\nphi_j = 0.5\na_0 = 1\na_inf = 1\neta_0 = 1\nmu_c = 1\n";
  std::string args = GetParam().args;
  for (auto [key, val] : {std::pair<std::string, std::string>{"{OUT}", out}, {"{DIR}", d.path.string()}}) {
    for (auto p = args.find(key); p != std::string::npos; p = args.find(key)) args.replace(p, key.size(), val);
  }
  for (bool pre_existing : {false, true}) {
    if (pre_existing) std::ofstream(out) << "keep me\n";
    const auto r = run(args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_NE(r.output.find(GetParam().message), std::string::npos) << r.output;
    if (pre_existing) {
      EXPECT_EQ(read_text(out), "keep me\n") << "output overwritten";
    } else {
      EXPECT_FALSE(fs::exists(out)) << "output created";
    }
    for (const auto& e : fs::directory_iterator(d.path)) {
      EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << "temporary left behind: " << e.path();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    RheologyCli, BadInput,
    ::testing::Values(
        BadCase{"rheology flow-curve --preset nosuch --phi 0.4 --out {OUT}", "unknown preset 'nosuch'"},
        BadCase{"rheology flow-curve --params {DIR}/miss.toml --phi 0.4 --out {OUT}", "steady.tau_star"},
        BadCase{"rheology flow-curve --params {DIR}/bad.toml --phi 0.4 --out {OUT}", "phi_c < phi_j"},
        BadCase{"rheology flow-curve --params {DIR}/neg.toml --phi 0.4 --out {OUT}", "steady.eta_0"},
        BadCase{"rheology flow-curve --params {DIR}/absent.toml --phi 0.4 --out {OUT}", "absent.toml: file not found"},
        BadCase{"rheology flow-curve --preset hermes2016 --phi 0 --out {OUT}", "must lie in (0, phi_j)"},
        BadCase{"rheology flow-curve --preset hermes2016 --phi 0.4 --phi 0.6 --out {OUT}", "phi_j = 0.535"},
        BadCase{"rheology flow-curve --preset hermes2016 --phi 0.4 --out {OUT} --plot {DIR}/nodir/x.png",
                "does not exist"},
        BadCase{"rheology flow-curve --preset hermes2016 --phi 0.4 --points 1 --out {OUT}", "--points"},
        BadCase{"rheology structure --out {OUT}", "--preset NAME or --params FILE"}));

// Reporting the error fails in turn (stderr on a full device: fmt::print throws): still an error
// exit with status 3, not an exception escaping main() and std::terminate's abort (status 134).
TEST(RheologyCli, ErrorThatCannotBeReportedIsStatus3NotAnAbort) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  clitest::TempDir d;
  const auto r = clitest::shell(fmt::format("({} rheology flow-curve --preset nosuch --phi 0.4 --out {} 2>/dev/full)",
                                            OOBLECK_CLI, d / "fc.csv"));
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_FALSE(fs::exists(d / "fc.csv"));
}

TEST(RheologyCli, UnwritableOutputFolder) {
  const auto r = run("rheology flow-curve --preset hermes2016 --phi 0.4 --out /nonexistent_dir/fc.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("/nonexistent_dir"), std::string::npos) << r.output;
}
