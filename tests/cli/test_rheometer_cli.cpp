// `oobleck rheology import` and `rheology fit --kind curves --data EXPORT --phi PHI` on the
// instrument-export fixtures of tests/rheology/data/rheometer (make_fixtures.py: hermes2016 flow
// curves at phi 0.40, 0.44, 0.46, 0.48, rate-controlled below 0.8 gamma_dot_DST, printed to 5
// significant digits in each instrument's units).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli_runner.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/rheology/params.hpp"

namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kDir = std::string(OOBLECK_SOURCE_DIR) + "/tests/rheology/data/rheometer/";

class RheometerCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("oobleck_rheometer_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

/// The four exports, one per phi, with the step that holds the flow curve where a file has several.
const std::string kExports = "--data " + kDir + "trios_phi040.txt --step 'Flow sweep' --phi 0.40 --data " + kDir +
                             "rheocompass_phi044.csv --step 2 --phi 0.44 --data " + kDir +
                             "rspace_phi046.csv --phi 0.46 --data " + kDir + "generic_phi048.csv --phi 0.48";

TEST_F(RheometerCli, ImportWritesEveryStepInSiAndReadsBackTheSameValues) {
  for (const char* name : {"trios_phi040.txt", "rheocompass_phi044.csv", "rspace_phi046.csv", "generic_phi048.csv"}) {
    const std::string out = path(std::string(name) + ".csv");
    const auto r =
        clitest::run(std::string("rheology import ").append(kDir).append(name).append(" --out ").append(out));
    ASSERT_EQ(r.status, 0) << r.output;
    const auto original = oobleck::io::read_rheometer(kDir + name);
    const auto imported = oobleck::io::read_rheometer(out);
    EXPECT_EQ(imported.format, oobleck::io::RheometerFormat::csv);
    ASSERT_EQ(imported.steps.size(), original.steps.size()) << name;
    for (std::size_t s = 0; s < original.steps.size(); ++s) {
      const auto& a = original.steps[s];
      const auto& b = imported.steps[s];
      EXPECT_EQ(b.name, a.name);
      EXPECT_EQ(b.index, a.index);
      ASSERT_EQ(b.rows(), a.rows());
      for (const char* col : {"time", "shear_rate", "shear_stress", "viscosity"}) {
        const auto* ca = a.find(col);
        const auto* cb = b.find(col);
        if (ca == nullptr) continue;
        ASSERT_NE(cb, nullptr) << name << " " << col;
        for (std::size_t i = 0; i < a.rows(); ++i) {
          if (std::isnan(ca->values[i])) {
            EXPECT_TRUE(std::isnan(cb->values[i]));
          } else {
            EXPECT_EQ(cb->values[i], ca->values[i]) << name << " " << col << " row " << i;  // shortest round trip
          }
        }
      }
    }
    const std::string text = clitest::read_text(out);
    EXPECT_THAT(text, HasSubstr("# units: time=s, shear_rate=1/s, shear_stress=Pa, viscosity=Pa s"));
    EXPECT_THAT(text, HasSubstr("\nstep,step_name,time,shear_rate,shear_stress,viscosity"));
  }
}

TEST_F(RheometerCli, ImportStepSelectsByNameWithoutTheTriosSuffix) {
  const std::string out = path("sweep.csv");
  const auto r = clitest::run("rheology import " + kDir + "trios_phi040.txt --step 'FLOW SWEEP' --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("steps 2 'Flow sweep - 2' (16 rows)"));
  const auto f = oobleck::io::read_rheometer(out);
  ASSERT_EQ(f.steps.size(), 1u);
  EXPECT_EQ(f.steps[0].name, "Flow sweep - 2");
  EXPECT_EQ(f.steps[0].rows(), 16u);
  // The first row of the sweep: 1.1001e-3 Pa at 1.0000e-2 1/s, 1.1001e2 mPa.s.
  EXPECT_DOUBLE_EQ(f.steps[0].find("shear_stress")->values[0], 1.1001e-3);
  EXPECT_DOUBLE_EQ(f.steps[0].find("viscosity")->values[0], 0.11001);
}

TEST_F(RheometerCli, JointFitOverFourExportsRecoversTheParametersTheyWereWrittenFrom) {
  // Start 10 % (1-2 % in phi) away from the truth.
  auto start = oobleck::rheology::load_preset("hermes2016");
  start.name = "start";
  start.steady.a_0 = 0.88;
  start.steady.a_inf = 0.72;
  start.steady.phi_j = 0.54;
  start.steady.phi_c = 0.43;
  start.steady.tau_star = 6.0;
  std::ofstream(path("start.toml")) << oobleck::rheology::to_toml(start);
  const auto r = clitest::run("rheology fit --kind curves " + kExports + " --params " + path("start.toml") +
                              " --parameters a_0,phi_j,a_inf,phi_c,tau_star --json --out " + path("fit.toml"));
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["n"], 64);
  // The data carry rounding to 5 digits (relative +-5e-5): the rms log residual is of that size.
  EXPECT_LT(j["rms"].get<double>(), 5e-5);
  const auto truth = oobleck::rheology::load_preset("hermes2016").steady;
  const std::vector<std::pair<std::string, double>> want = {{"a_0", truth.a_0},
                                                            {"phi_j", truth.phi_j},
                                                            {"a_inf", truth.a_inf},
                                                            {"phi_c", truth.phi_c},
                                                            {"tau_star", truth.tau_star}};
  for (const auto& [name, value] : want) {
    const double v = j["parameters"][name]["value"], se = j["parameters"][name]["std_error"];
    EXPECT_LT(std::abs(v - value), 3.0 * se) << name << " = " << v << " +- " << se << ", truth " << value;
    EXPECT_LT(std::abs(v - value), 1e-3 * value) << name;  // and within 0.1 %
  }
  EXPECT_THAT(clitest::read_text(path("fit.toml")),
              HasSubstr("fitted by: oobleck rheology fit --kind curves --data " + kDir +
                        "trios_phi040.txt --step 'Flow sweep' --phi 0.4 --data"));
}

TEST_F(RheometerCli, BadExportsAndOptionsAreInputErrorsThatWriteNothing) {
  auto expect_error = [&](const std::string& args, const std::string& message) {
    const auto r = clitest::run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(message)) << args;
    EXPECT_FALSE(fs::exists(path("out.csv")));
    EXPECT_FALSE(fs::exists(path("fit.toml")));
  };
  std::ofstream(path("bad_unit.txt")) << "Filename\tx.tri\n\n[step]\nFlow sweep - 1\nStress\tShear rate\nPa\t1/min2\n"
                                         "1\t2\n";
  expect_error("rheology import " + path("bad_unit.txt") + " --out " + path("out.csv"),
               "bad_unit.txt:6: column 'Shear rate': unknown unit '1/min2'; expected one of");
  expect_error("rheology import " + kDir + "trios_phi040.txt --step 'Flow sweeps' --out " + path("out.csv"),
               "--step = 'Flow sweeps': no such step");
  expect_error("rheology import " + kDir + "trios_phi040.txt --format lims --out " + path("out.csv"),
               "--format = 'lims': must be one of auto, trios, rheocompass");
  const std::string fit = "rheology fit --kind curves --preset hermes2016 --out " + path("fit.toml") + " ";
  expect_error(fit + "--data " + kDir + "trios_phi040.txt",
               "a trios export has no phi column: give its volume fraction");
  expect_error(fit + "--data " + kDir + "trios_phi040.txt --phi 0.40",
               "2 steps hold shear rate and stress (1 'Peak hold - 1', 2 'Flow sweep - 2'): choose one with --step "
               "NAME or INDEX");
  expect_error(fit + "--data " + kDir + "trios_phi040.txt --data " + kDir + "rspace_phi046.csv --phi 0.4",
               "--data given 2 times and --phi 1 times");
  expect_error("rheology fit --kind low --preset hermes2016 --out " + path("fit.toml") + " --data " + kDir +
                   "generic_phi048.csv --phi 0.48",
               "--phi: only for --kind curves");
}

}  // namespace
