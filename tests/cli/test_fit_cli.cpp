// Contract of `oobleck rheology fit` (apps/cmd_fit.cpp): output created on success and loadable by
// the other commands; bad input exits non-zero without creating or overwriting the output.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"
#include "oobleck/rheology/steady_states.hpp"

namespace {
namespace fs = std::filesystem;

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// A fresh, empty folder per test, removed afterwards.
class FitCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / (std::string("oobleck_fit_cli_") + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// Runs the CLI with `args`; stdout to out.txt, stderr to err.txt; returns the exit status.
  int run(const std::string& args) {
    const std::string cmd =
        std::string(OOBLECK_CLI) + " " + args + " > '" + path("out.txt") + "' 2> '" + path("err.txt") + "'";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  std::string read(const std::string& name) const {
    std::ifstream in(path(name));
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }

  /// Minimum viscosities [Pa s] of hermes2016 from E12 (exact, no noise) at 12 volume fractions.
  std::string low_csv() const {
    const auto p = oobleck::rheology::load_preset("hermes2016").steady;
    std::string s = "# minimum viscosities\nphi,viscosity\n";
    for (int k = 0; k < 12; ++k) {
      const double phi = 0.2 + 0.3 * k / 11.0;
      // 1 % deterministic scatter so that the residual variance is not zero.
      const double v = oobleck::rheology::eta_r_low(p, phi) * p.eta_0 * (1.0 + 0.01 * std::sin(7.0 * k));
      s += std::to_string(phi) + "," + std::to_string(v) + "\n";
    }
    return s;
  }

  fs::path dir_;
};

TEST_F(FitCli, SuccessWritesLoadableToml) {
  write("low.csv", low_csv());
  ASSERT_EQ(run("rheology fit --kind low --data " + path("low.csv") + " --preset hermes2016 --out " + path("fit.toml")),
            0)
      << read("err.txt");
  ASSERT_TRUE(fs::exists(path("fit.toml")));
  const auto fitted = oobleck::rheology::load_params_file(path("fit.toml"));
  EXPECT_NEAR(fitted.steady.phi_j, 0.535, 0.005);
  EXPECT_NEAR(fitted.steady.a_0, 0.8, 0.05);
  EXPECT_EQ(fitted.steady.mu_c, 1.19);  // fixed
  const std::string toml = read("fit.toml");
  EXPECT_NE(toml.find("# fitted values with 1-sigma standard errors"), std::string::npos);
  EXPECT_NE(toml.find("#   phi_j = "), std::string::npos);
  const std::string out = read("out.txt");
  EXPECT_NE(out.find("phi_j"), std::string::npos) << out;
  EXPECT_NE(out.find("rms log residual"), std::string::npos) << out;
  // The file is usable by the other commands.
  EXPECT_EQ(run("rheology dst --params " + path("fit.toml") + " --phi 0.5"), 0) << read("err.txt");
}

TEST_F(FitCli, JsonAndRelativeViscosityAndDefaultBase) {
  const auto p = oobleck::rheology::load_preset("hermes2016").steady;
  std::string csv = "phi,relative_viscosity\n";
  for (int k = 0; k < 10; ++k) {
    const double phi = 0.2 + 0.2 * k / 9.0;
    csv += std::to_string(phi) + "," +
           std::to_string(oobleck::rheology::eta_r_high(p, phi) * (1.0 + 0.01 * std::cos(5.0 * k))) + "\n";
  }
  write("high.csv", csv);
  ASSERT_EQ(run("rheology fit --kind high --data " + path("high.csv") + " --out " + path("fit.toml") + " --json"), 0)
      << read("err.txt");
  const auto j = nlohmann::json::parse(read("out.txt"));
  EXPECT_EQ(j.at("kind"), "high");
  EXPECT_EQ(j.at("n"), 10);
  EXPECT_LT(j.at("rms").get<double>(), 0.02);
  EXPECT_NEAR(j.at("parameters").at("phi_c").at("value").get<double>(), 0.436, 0.003);
  EXPECT_GT(j.at("parameters").at("a_inf").at("std_error").get<double>(), 0.0);
  EXPECT_NE(read("err.txt").find("using the hermes2016 preset"), std::string::npos);  // not on stdout with --json
  // Without --json the note is on stdout.
  ASSERT_EQ(run("rheology fit --kind high --data " + path("high.csv") + " --out " + path("fit2.toml")), 0);
  EXPECT_NE(read("out.txt").find("using the hermes2016 preset"), std::string::npos);
}

TEST_F(FitCli, MalformedCsvFailsWithoutOutput) {
  write("bad.csv", "phi,viscosity\n0.3,0.02\n0.4,zero\n0.5,0.1\n");
  EXPECT_EQ(run("rheology fit --kind low --data " + path("bad.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_FALSE(fs::exists(path("fit.toml")));
  EXPECT_NE(read("err.txt").find("'zero' is not a finite number"), std::string::npos) << read("err.txt");
  write("ragged.csv", "phi,viscosity\n0.3,0.02,7\n");
  EXPECT_EQ(run("rheology fit --kind low --data " + path("ragged.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_FALSE(fs::exists(path("fit.toml")));
}

TEST_F(FitCli, MissingColumnFailsWithoutOutput) {
  write("rates.csv", "phi,rate\n0.45,1\n0.47,0.5\n0.5,0.1\n");
  EXPECT_EQ(run("rheology fit --kind dst --data " + path("rates.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_FALSE(fs::exists(path("fit.toml")));
  const std::string err = read("err.txt");
  EXPECT_NE(err.find("missing column 'shear_rate_dst'"), std::string::npos) << err;
  EXPECT_NE(err.find("rates.csv"), std::string::npos) << err;
}

TEST_F(FitCli, BadValuesFailWithoutOutput) {
  write("neg.csv", "phi,viscosity\n0.3,0.02\n0.4,-0.03\n0.5,0.1\n");
  EXPECT_EQ(run("rheology fit --kind low --data " + path("neg.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_NE(read("err.txt").find("column 'viscosity' = -0.03: must be positive"), std::string::npos);
  write("few.csv", "phi,viscosity\n0.3,0.02\n0.4,0.03\n");
  EXPECT_EQ(run("rheology fit --kind low --data " + path("few.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_NE(read("err.txt").find("need at least 3 points"), std::string::npos) << read("err.txt");
  EXPECT_FALSE(fs::exists(path("fit.toml")));
}

TEST_F(FitCli, UnwritableOutputFails) {
  write("low.csv", low_csv());
  EXPECT_EQ(run("rheology fit --kind low --data " + path("low.csv") + " --out " + path("missing/fit.toml")), 2);
  EXPECT_FALSE(fs::exists(path("missing")));
  EXPECT_NE(read("err.txt").find("cannot write output"), std::string::npos) << read("err.txt");
  // A folder as output.
  fs::create_directories(path("folder.toml"));
  EXPECT_EQ(run("rheology fit --kind low --data " + path("low.csv") + " --out " + path("folder.toml")), 2);
}

TEST_F(FitCli, ExistingOutputNotOverwrittenOnError) {
  write("fit.toml", "sentinel\n");
  write("bad.csv", "phi,viscosity\n0.3,\n");
  EXPECT_EQ(run("rheology fit --kind low --data " + path("bad.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_EQ(read("fit.toml"), "sentinel\n");
  write("low.csv", low_csv());
  EXPECT_EQ(run("rheology fit --kind dst --data " + path("low.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_EQ(read("fit.toml"), "sentinel\n");
  EXPECT_EQ(run("rheology fit --kind low --terms 2 --data " + path("low.csv") + " --out " + path("fit.toml")), 2);
  EXPECT_EQ(read("fit.toml"), "sentinel\n");
  for (const auto& e : fs::directory_iterator(dir_)) {  // no temporaries left behind
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
}

TEST_F(FitCli, DstFitWithPlot) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for the plot";
  const auto p = oobleck::rheology::load_preset("dhaene1993").steady;
  std::string csv = "phi,shear_rate_dst\n";
  for (int k = 0; k < 8; ++k) {
    const double phi = 0.575 + 0.07 * k / 7.0;
    csv += std::to_string(phi) + "," +
           std::to_string(*oobleck::rheology::shear_rate_dst(p, phi) * (1.0 + 0.01 * std::sin(3.0 * k))) + "\n";
  }
  write("dst.csv", csv);
  ASSERT_EQ(run("rheology fit --kind dst --data " + path("dst.csv") + " --preset dhaene1993 --out " + path("fit.toml") +
                " --plot " + path("fit.png")),
            0)
      << read("err.txt");
  EXPECT_TRUE(fs::exists(path("fit.png")));
  EXPECT_GT(fs::file_size(path("fit.png")), 1000u);
  const auto fitted = oobleck::rheology::load_params_file(path("fit.toml"));
  ASSERT_EQ(fitted.steady.eta_B_terms.size(), 1u);
  EXPECT_NEAR(fitted.steady.eta_B_terms[0].alpha, 6.0, 0.1);
}

TEST_F(FitCli, UnknownKindListsEveryKind) {
  write("low.csv", low_csv());
  EXPECT_EQ(run("rheology fit --kind mid --data " + path("low.csv") + " --out " + path("fit.toml")), 2);
  const std::string err = read("err.txt");
  for (const char* k : {"'mid'", "low (", "high (", "dst (", "curves ("})
    EXPECT_NE(err.find(k), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("fit.toml")));
}

TEST_F(FitCli, CurvesFitWithPlot) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for the plot";
  // Points of hermes2016's flow curves at 5 phi (every branch), rates with 2 % deterministic scatter.
  const auto p = oobleck::rheology::load_preset("hermes2016").steady;
  std::string csv = "phi,shear_rate,shear_stress\n";
  int k = 0;
  for (double phi : {0.40, 0.44, 0.46, 0.48, 0.50}) {
    const auto curve = oobleck::rheology::flow_curve(p, phi, 200);
    for (std::size_t i = 20; i < curve.size(); i += 18, ++k) {
      csv += fmt(phi) + "," + fmt(curve[i].shear_rate * (1.0 + 0.02 * std::sin(5.0 * k))) + "," +
             fmt(curve[i].shear_stress) + "\n";
    }
  }
  write("curves.csv", csv);
  const std::string args = "rheology fit --kind curves --data " + path("curves.csv") +
                           " --preset hermes2016 --parameters a_0,phi_j,tau_star --out " + path("fit.toml");
  ASSERT_EQ(run(args + " --plot " + path("fit.png")), 0) << read("err.txt");
  EXPECT_NE(read("out.txt").find("wrote " + path("fit.png")), std::string::npos) << read("out.txt");
  EXPECT_GT(fs::file_size(path("fit.png")), 1000u);
  const auto fitted = oobleck::rheology::load_params_file(path("fit.toml"));
  EXPECT_NEAR(fitted.steady.phi_j, p.phi_j, 1e-3);
  EXPECT_NEAR(fitted.steady.tau_star, p.tau_star, 0.05 * p.tau_star);
  // An unwritable plot fails before the fit and leaves the parameter file alone.
  write("fit.toml", "sentinel\n");
  EXPECT_EQ(run(args + " --plot " + path("missing/fit.png")), 2);
  EXPECT_EQ(read("fit.toml"), "sentinel\n");
  for (const auto& e : fs::directory_iterator(dir_)) {  // no temporaries left behind
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
}

TEST_F(FitCli, CurvesFitHoldsWhatTheDataDoNotDetermineWithAWarning) {
  // Rate-controlled hermes2016 curves below DST (12 rates per phi up to 0.8 gamma_dot_DST, 2 %
  // deterministic scatter on the stress): the second eta_B term (alpha = 0.1) is not determined.
  const auto p = oobleck::rheology::load_preset("hermes2016").steady;
  std::string csv = "phi,shear_rate,shear_stress\n";
  int k = 0;
  for (double phi : {0.40, 0.4225, 0.445, 0.4675, 0.49}) {
    const auto dst = oobleck::rheology::shear_rate_dst(p, phi);
    const double hi = dst ? 0.8 * *dst : 10.0;
    for (int i = 0; i < 12; ++i, ++k) {
      const double rate = 1e-3 * std::pow(hi / 1e-3, i / 11.0);
      const auto s = oobleck::rheology::steady_states_at(p, phi, oobleck::rheology::Control::shear_rate, rate);
      csv += fmt(phi) + "," + fmt(rate) + "," + fmt(s.at(0).shear_stress * (1.0 + 0.02 * std::sin(5.0 * k))) + "\n";
    }
  }
  write("curves.csv", csv);
  const std::string args =
      "rheology fit --kind curves --data " + path("curves.csv") + " --preset hermes2016 --out " + path("fit.toml");
  ASSERT_EQ(run(args), 0) << read("err.txt");
  const std::string err = read("err.txt"), toml = read("fit.toml"), out = read("out.txt");
  EXPECT_NE(
      err.find("warning: eta_B[1].phi_i held at the base value 0.0093 [1/(Pa s)]: the data do not determine it ("),
      std::string::npos)
      << err;
  EXPECT_NE(out.find("  eta_B[1].phi_i = 0.0093       held (base value)"), std::string::npos) << out;
  EXPECT_NE(err.find("parameters held (eta_B[1].phi_i"), std::string::npos) << err;
  EXPECT_NE(err.find("--strict makes this an error"), std::string::npos) << err;
  EXPECT_NE(toml.find("# held at the base set's values because the data do not determine them"), std::string::npos)
      << toml;
  EXPECT_NE(toml.find("#   eta_B[1].phi_i = 0.0093 [1/(Pa s)]: 1 sigma: a factor "), std::string::npos) << toml;
  const auto fitted = oobleck::rheology::load_params_file(path("fit.toml"));
  EXPECT_EQ(fitted.steady.eta_B_terms.at(1).phi_i, p.eta_B_terms.at(1).phi_i);

  ASSERT_EQ(run(args + " --json"), 0) << read("err.txt");
  const auto j = nlohmann::json::parse(read("out.txt"));
  ASSERT_GE(j["held"].size(), 1u);
  EXPECT_EQ(j["held"][0]["name"], "eta_B[1].phi_i");
  EXPECT_EQ(j["held"][0]["value"].get<double>(), p.eta_B_terms.at(1).phi_i);
  EXPECT_NE(j["held"][0]["reason"].get<std::string>().find("1 sigma: a factor"), std::string::npos);
  EXPECT_EQ(j["parameters"].size() + j["held"].size(), 9u);
  // the correlation matrix's rows and columns are in the fit's order, which "correlation_order" gives
  EXPECT_EQ(j["correlation_order"][0], "a_0");
  EXPECT_EQ(j["correlation"].size(), j["parameters"].size() * j["parameters"].size());
  for (const auto& h : j["held"]) EXPECT_EQ(h["name"].get<std::string>().rfind("eta_B[", 0), 0u) << h;
  const std::pair<const char*, double> truth[] = {
      {"a_0", p.a_0}, {"phi_j", p.phi_j}, {"phi_c", p.phi_c}, {"tau_star", p.tau_star}};
  for (const auto& [name, value] : truth) {
    const auto& q = j["parameters"][name];
    EXPECT_LT(std::fabs(q["value"].get<double>() - value), 3.0 * q["std_error"].get<double>()) << name << q;
  }

  // --strict: today's error, and no output.
  fs::remove(path("fit.toml"));
  EXPECT_EQ(run(args + " --strict"), 2);
  EXPECT_NE(read("err.txt").find("the data do not determine"), std::string::npos) << read("err.txt");
  EXPECT_FALSE(fs::exists(path("fit.toml")));
  write("low.csv", low_csv());
  EXPECT_EQ(run("rheology fit --kind low --data " + path("low.csv") + " --preset hermes2016 --strict --out " +
                path("fit.toml")),
            2);
  EXPECT_NE(read("err.txt").find("--strict: only for --kind curves"), std::string::npos) << read("err.txt");
}

}  // namespace
