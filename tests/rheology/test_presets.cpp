// Presets: the shipped TOML files hold the paper's Tables 1–3, and bad parameter files are
// rejected with messages naming the file, the key and the rule.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/params.hpp"
#include "paper_tables.hpp"

using namespace oobleck;

TEST(Presets, AllEightMatchThePaperTables) {
  ASSERT_EQ(rheology::preset_names().size(), paper::fits().size());
  for (const auto& fit : paper::fits()) {
    SCOPED_TRACE(fit.name);
    const auto p = rheology::load_preset(fit.name);
    EXPECT_EQ(p.name, fit.name);
    EXPECT_DOUBLE_EQ(p.steady.phi_c, fit.phi_c);
    EXPECT_DOUBLE_EQ(p.steady.phi_j, fit.phi_j);
    EXPECT_DOUBLE_EQ(p.steady.a_0, fit.a_0);
    EXPECT_DOUBLE_EQ(p.steady.a_inf, fit.a_inf);
    EXPECT_DOUBLE_EQ(p.steady.tau_star, fit.tau_star);
    EXPECT_DOUBLE_EQ(p.steady.eta_0, fit.eta_0);
    EXPECT_DOUBLE_EQ(p.steady.mu_c, fit.mu_c);
    EXPECT_DOUBLE_EQ(p.steady.Delta, fit.Delta);
    ASSERT_EQ(p.steady.eta_B_terms.size(), fit.terms.size());
    for (std::size_t i = 0; i < fit.terms.size(); ++i) {
      EXPECT_DOUBLE_EQ(p.steady.eta_B_terms[i].phi_i, fit.terms[i].phi_i);
      EXPECT_DOUBLE_EQ(p.steady.eta_B_terms[i].alpha, fit.terms[i].alpha);
    }
    // Cornstarch defaults of the dynamic scenes (scenes.md): d = 5.85 um, rho_s = 1620, K_3 = 4.715.
    EXPECT_DOUBLE_EQ(p.granular.d, 5.85e-6);
    EXPECT_DOUBLE_EQ(p.granular.rho_s, 1620.0);
    EXPECT_DOUBLE_EQ(p.granular.K_3, 4.715);
  }
}

namespace {
struct TempToml {
  std::string path;
  explicit TempToml(const std::string& text) {
    path = (std::filesystem::temp_directory_path() /
            ("oobleck_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".toml"))
               .string();
    std::ofstream(path) << text;
  }
  ~TempToml() { std::remove(path.c_str()); }
};

const char* kGood = R"(
name = "mine"
[steady]
phi_c = 0.436
phi_j = 0.535
a_0 = 0.8
a_inf = 0.8
tau_star = 5.35
eta_0 = 6e-3
mu_c = 1.19
[[steady.eta_B]]
phi_i = 1.86e4
alpha = 4
)";

std::string error_of(const std::string& text) {
  TempToml f(text);
  try {
    rheology::load_params_file(f.path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}
}  // namespace

TEST(Presets, UserFileLoadsAndRoundTrips) {
  TempToml f(kGood);
  const auto p = rheology::load_params_file(f.path);
  EXPECT_EQ(p.name, "mine");
  EXPECT_DOUBLE_EQ(p.steady.Delta, 0.0);  // default
  EXPECT_DOUBLE_EQ(p.granular.G, 3.8e5);  // default
  TempToml g(rheology::to_toml(p));
  const auto q = rheology::load_params_file(g.path);
  EXPECT_EQ(q.steady.phi_j, p.steady.phi_j);
  EXPECT_EQ(q.steady.eta_B_terms.size(), 1u);
  EXPECT_EQ(q.steady.eta_B_terms[0].phi_i, 1.86e4);
}

TEST(Presets, BadFilesNameFileKeyAndRule) {
  std::string e = error_of(replace(kGood, "phi_c = 0.436", "phi_c = 0.6"));
  EXPECT_NE(e.find("steady.phi_c"), std::string::npos) << e;
  EXPECT_NE(e.find("phi_c < phi_j"), std::string::npos) << e;
  EXPECT_NE(e.find(".toml"), std::string::npos) << e;

  e = error_of(replace(kGood, "eta_0 = 6e-3", "eta_0 = -6e-3"));
  EXPECT_NE(e.find("steady.eta_0"), std::string::npos) << e;
  EXPECT_NE(e.find("positive"), std::string::npos) << e;

  e = error_of(replace(kGood, "mu_c = 1.19\n", ""));
  EXPECT_NE(e.find("steady.mu_c"), std::string::npos) << e;
  EXPECT_NE(e.find("missing"), std::string::npos) << e;

  e = error_of(replace(kGood, "tau_star", "tau_str"));
  EXPECT_NE(e.find("steady.tau_str"), std::string::npos) << e;  // unknown key, named
  EXPECT_NE(e.find("unknown"), std::string::npos) << e;

  e = error_of(replace(kGood, "a_0 = 0.8", "a_0 = \"big\""));
  EXPECT_NE(e.find("steady.a_0"), std::string::npos) << e;
  EXPECT_NE(e.find("number"), std::string::npos) << e;

  e = error_of(replace(kGood, "[steady]", "[steady\n"));
  EXPECT_NE(e.find("syntax"), std::string::npos) << e;

  e = error_of(replace(kGood, "alpha = 4", "alpha = -4"));
  EXPECT_NE(e.find("steady.eta_B[0].alpha"), std::string::npos) << e;
}

TEST(Presets, UnknownPresetListsTheKnownOnes) {
  try {
    rheology::load_preset("hermes2061");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("unknown preset 'hermes2061'"), std::string::npos) << m;
    EXPECT_NE(m.find("did you mean 'hermes2016'"), std::string::npos) << m;
  }
}
