// The `oobleck rheology` CLI contract: file formats, JSON shape, and bad input -> clear message,
// non-zero exit, no output file created or overwritten.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "oobleck/rheology/params.hpp"
#include "oobleck/rheology/steady_states.hpp"

namespace fs = std::filesystem;
using clitest::run;

using clitest::read_text;

TEST(RheologyCli, FlowCurveCsvHasContractColumnsAndOrderedRows) {
  clitest::TempDir d;
  const auto r = run("rheology flow-curve --preset hermes2016 --phi 0.40 --phi 0.47 --points 50 --out " + d / "fc.csv");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(d / "fc.csv");
  std::string units, header;
  std::getline(in, units);  // one comment line with the units, then the columns
  EXPECT_EQ(units.rfind("# units: phi=1, f=1, shear_rate=1/s, shear_stress=Pa, granular_pressure=Pa, "
                        "granular_shear_stress=Pa, viscosity=Pa s, eta_r=1, shear_rate_dst=1/s; parameters hermes2016",
                        0),
            0u)
      << units;
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
  const std::string text = read_text(d / "f.csv");
  EXPECT_EQ(text.rfind("# units: stress=eta_0 gamma_dot_0, f_model=1, f_wyart_cates=1, f_singh=1; parameters "
                       "singh2018a (normalized units)\nstress,f_model,f_wyart_cates,f_singh\n",
                       0),
            0u)
      << text.substr(0, 200);
}

/// The measured points of hermes2016 at phi 0.40 and 0.47 (rates below DST), 6 per phi.
std::string hermes_points() {
  const auto p = oobleck::rheology::load_preset("hermes2016").steady;
  std::string csv = "# units: phi=1, shear_rate=1/s, shear_stress=Pa\nphi,shear_rate,shear_stress\n";
  for (double phi : {0.40, 0.47}) {
    for (int k = 0; k < 6; ++k) {
      const double rate = 0.01 * std::pow(10.0, 0.4 * k);
      const auto s = oobleck::rheology::steady_states_at(p, phi, oobleck::rheology::Control::shear_rate, rate);
      csv += fmt::format("{},{},{}\n", phi, rate, s.at(0).shear_stress * (1.0 + 0.02 * std::sin(3.0 * k)));
    }
  }
  return csv;
}

TEST(RheologyCli, FlowCurvePlotWithoutOut) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for the plot";
  clitest::TempDir d;
  auto r = run("rheology flow-curve --preset hermes2016 --phi 0.45 --phi 0.5 --plot " + d / "fc.png");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(fs::file_size(d / "fc.png"), 1000u);
  EXPECT_EQ(r.output, "wrote " + d / "fc.png" + "\n");
  for (const auto& e : fs::directory_iterator(d.path)) EXPECT_EQ(e.path().filename(), "fc.png");
  // Neither --out nor --plot: a usage error (exit 1) that says what to give.
  r = run("rheology flow-curve --preset hermes2016 --phi 0.45");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("oobleck: error: --out/--plot: give --out CSV, --plot PNG or both"), std::string::npos)
      << r.output;
}

TEST(RheologyCli, FlowCurveDrawsMeasuredDataOverTheModel) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for the plot";
  clitest::TempDir d;
  const std::string points = hermes_points();
  std::ofstream(d / "data.csv") << points;
  // The plotting script's interpreter is a wrapper that keeps a copy of the data CSV it is given.
  std::ofstream(d / "python") << "#!/bin/sh\nprev=\nfor a in \"$@\"; do\n  [ \"$prev\" = --data ] && cp \"$a\" '"
                              << d / "seen.csv"
                              << "'\n  prev=$a\ndone\nprintf '%s\\n' \"$@\" > '" << d / "args.txt"
                              << "'\nexec /usr/bin/python3 \"$@\"\n";
  fs::permissions(d / "python", fs::perms::owner_all);
  const std::string command = "OOBLECK_PYTHON=" + d / "python" + " " + OOBLECK_CLI +
                              " rheology flow-curve --preset hermes2016 --data " + d / "data.csv" + " --plot " +
                              d / "fc.png";
  const std::string said = "data: " + d / "data.csv" + ": 12 points at phi = 0.4, 0.47\n";
  for (const std::string axes : {"", " --y viscosity", " --x stress --y viscosity --xlim 1e-4,10 --ylim 0.01,10"}) {
    SCOPED_TRACE(axes);
    fs::remove(d / "fc.png");
    const auto r = clitest::shell(command + axes);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(said), std::string::npos) << r.output;
    EXPECT_GT(fs::file_size(d / "fc.png"), 1000u);
    // The script read the data rows: the same phi, rates and stresses (17 significant digits).
    std::ifstream seen(d / "seen.csv"), given(d / "data.csv");
    std::string a, b;
    std::getline(seen, a);  // its own units line
    EXPECT_EQ(a.rfind("# units: phi=1, shear_rate=1/s, shear_stress=Pa", 0), 0u) << a;
    std::getline(given, b);
    for (std::getline(seen, a), std::getline(given, b); std::getline(seen, a) && std::getline(given, b);) {
      double x[3], y[3];
      ASSERT_EQ(std::sscanf(a.c_str(), "%lf,%lf,%lf", &x[0], &x[1], &x[2]), 3) << a;
      ASSERT_EQ(std::sscanf(b.c_str(), "%lf,%lf,%lf", &y[0], &y[1], &y[2]), 3) << b;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(x[k], y[k]) << a << " vs " << b;
    }
    EXPECT_FALSE(std::getline(given, b)) << "not every data row reached the plot";
    const std::string args = read_text(d / "args.txt");
    EXPECT_NE(args.find(axes.find("stress") != std::string::npos ? "--x\nstress\n" : "--x\nrate\n"), std::string::npos)
        << args;
    if (axes.find("xlim") != std::string::npos) {
      EXPECT_NE(args.find("--xlim\n0.0001,10\n"), std::string::npos) << args;
    }
  }
  for (const auto& e : fs::directory_iterator(d.path)) {  // no temporaries: the model CSV lived in /tmp
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
}

TEST(RheologyCli, FlowCurveDrawsAnInstrumentExport) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for the plot";
  clitest::TempDir d;
  const std::string fixture = std::string(OOBLECK_SOURCE_DIR) + "/tests/rheology/data/rheometer/trios_phi040.txt";
  const auto r =
      run("rheology flow-curve --preset hermes2016 --data " + fixture +
          " --step 'Flow sweep' --phi 0.40 --x stress --y viscosity --out " + d / "fc.csv" + " --plot " + d / "fc.png");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("(trios): phi = 0.4, 16 points from step 'Flow sweep - 2'"), std::string::npos) << r.output;
  EXPECT_GT(fs::file_size(d / "fc.png"), 1000u);
  EXPECT_NE(read_text(d / "fc.csv").find("\n0.40000000000000002,"),
            std::string::npos);  // the model at the export's phi
}

TEST(RheologyCli, FlowCurvePlotOptionsAreCheckedBeforeAnyOutput) {
  clitest::TempDir d;
  std::ofstream(d / "data.csv") << hermes_points();
  const std::string base = "rheology flow-curve --preset hermes2016 --phi 0.45 --out " + d / "fc.csv";
  const std::pair<std::string, std::string> cases[] = {
      {base + " --plot " + d / "fc.png" + " --xlim 5,1", "--xlim: '5,1': must be LO,HI with 0 < LO < HI"},
      {base + " --plot " + d / "fc.png" + " --ylim abc", "--ylim: 'abc': must be LO,HI"},
      {base + " --plot " + d / "fc.png" + " --xlim 0,1", "--xlim: '0,1'"},
      {base + " --plot " + d / "fc.png" + " --x stress", "--x stress with --y stress"},
      {base + " --plot " + d / "fc.png" + " --y strain", "--y"},
      {base + " --xlim 1,2", "--xlim: draws on the plot: give --plot PNG"},
      {"rheology flow-curve --preset hermes2016 --data " + d / "data.csv" + " --out " + d / "fc.csv",
       "--data: draws on the plot"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = run(args);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << "\n" << r.output;
    EXPECT_FALSE(fs::exists(d / "fc.csv")) << args;
    EXPECT_FALSE(fs::exists(d / "fc.png")) << args;
  }
  // Data at or above the preset's phi_j: an input error naming it (exit 2).
  std::ofstream(d / "dense.csv") << "phi,shear_rate,shear_stress\n0.6,1,1\n0.6,2,3\n";
  const auto r = run("rheology flow-curve --preset hermes2016 --data " + d / "dense.csv" + " --plot " + d / "fc.png");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("phi_j = 0.535"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d / "fc.png"));
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
