// The parameter table (rheology/parameter_table.hpp): every row reaches its own member, the
// preset reader and writer and the validation follow it, and docs/scenes.md lists it as it is.
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/parameter_table.hpp"
#include "oobleck/rheology/params.hpp"

namespace {

using oobleck::InputError;
using namespace oobleck::rheology;

TEST(ParameterTable, EveryRowNamesOneMemberOfItsSectionAndNoTwoRowsShareOne) {
  std::set<std::string> keys;
  Preset p;
  FluidParams f;
  for (const Parameter& row : parameter_table()) {
    const int members = (row.steady != nullptr) + (row.granular != nullptr) + (row.fluid != nullptr);
    EXPECT_EQ(members, 1) << row.name;
    EXPECT_EQ(row.steady != nullptr, row.section == Section::Steady) << row.name;
    EXPECT_EQ(row.fluid != nullptr, row.section == Section::Fluid) << row.name;
    EXPECT_TRUE(keys.insert(fmt::format("{}.{}", section_name(row.section), row.name)).second) << row.name;
    EXPECT_FALSE(row.unit.empty()) << row.name;
    EXPECT_FALSE(row.meaning.empty()) << row.name;
    EXPECT_EQ(row.equation.substr(0, 1), "E") << row.name;
    // Writing through the row changes its member and no other.
    double& v = row.section == Section::Fluid ? value(f, row) : value(p, row);
    v = 12345.0;
  }
  int marked = 0;
  for (const Parameter& row : parameter_table()) {
    const double v = row.section == Section::Fluid ? value(f, row) : value(p, row);
    marked += v == 12345.0;
  }
  EXPECT_EQ(marked, static_cast<int>(parameter_table().size()));
  // No member without a row: the structs hold nothing but the rows' doubles (and the E8 terms).
  std::size_t rows[3] = {0, 0, 0};
  for (const Parameter& row : parameter_table()) ++rows[static_cast<int>(row.section)];
  EXPECT_EQ(sizeof(SteadyParams), rows[0] * sizeof(double) + sizeof(std::vector<EtaBTerm>));
  EXPECT_EQ(sizeof(GranularParams), rows[1] * sizeof(double));
  EXPECT_EQ(sizeof(FluidParams), rows[2] * sizeof(double));
}

TEST(ParameterTable, RulesReadAsTheRanges) {
  EXPECT_EQ(rule(parameter(Section::Steady, "tau_star")), "must be positive [Pa]");
  EXPECT_EQ(rule(parameter(Section::Steady, "phi_c")), "must lie in (0, 1)");
  EXPECT_EQ(rule(parameter(Section::Steady, "Delta")), "must lie in [0, 1]");
  EXPECT_EQ(rule(parameter(Section::Steady, "xi_dot_eps")), "must be >= 0 [1/s]");
  EXPECT_EQ(rule(parameter(Section::Fluid, "rho_f")), "must be positive [kg/m^3]");
  const Parameter& delta = parameter(Section::Steady, "Delta");
  EXPECT_TRUE(admissible(delta, 0.0));
  EXPECT_TRUE(admissible(delta, 1.0));
  EXPECT_FALSE(admissible(delta, 1.0 + 1e-12));
  EXPECT_FALSE(admissible(delta, std::nan("")));
  const Parameter& mu_2 = parameter(Section::Granular, "mu_2");
  EXPECT_TRUE(admissible(mu_2, -1.0));  // unset: mu_2 = mu_c
  Preset p = load_preset("hermes2016");
  p.granular.mu_2 = -1.0;
  EXPECT_EQ(effective_value(p, mu_2), p.steady.mu_c);
  EXPECT_THROW(
      {
        try {
          (void)parameter(Section::Granular, "K4");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("did you mean 'K_4'"), std::string::npos) << e.what();
          throw;
        }
      },
      InputError);
}

TEST(ParameterTable, ValidationRejectsEachParameterOutsideItsRangeByName) {
  for (const Parameter& row : parameter_table()) {
    if (row.section == Section::Fluid) continue;
    Preset p = load_preset("hermes2016");
    // Just below the lower end (or NaN where the range has none).
    value(p, row) = std::isfinite(row.lower) ? row.lower - (row.lower_open ? 0.0 : 1e-9) : std::nan("");
    if (!row.unset_means.empty()) value(p, row) = std::numeric_limits<double>::infinity();
    try {
      validate(p, "file.toml");
      ADD_FAILURE() << row.name << " = " << value(p, row) << " passed validation";
    } catch (const InputError& e) {
      const std::string key = fmt::format("key '{}.{}'", section_name(row.section), row.name);
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

TEST(ParameterTable, PresetFilesRoundTripEveryParameter) {
  Preset p = load_preset("hermes2016");
  double x = 0.11;
  for (const Parameter& row : parameter_table()) {
    if (row.section == Section::Fluid) continue;
    // A value inside the range, different for every row.
    x += 0.01;
    value(p, row) = std::isfinite(row.upper) ? row.lower + x * (row.upper - row.lower) : 1.0 + x;
  }
  p.steady.phi_c = 0.5;
  p.steady.phi_j = 0.6;
  p.granular.mu_2 = p.steady.mu_c + 0.25;
  const std::string path = testing::TempDir() + "parameter_table_round_trip.toml";
  std::ofstream(path) << to_toml(p);
  const Preset q = load_params_file(path);
  for (const Parameter& row : parameter_table()) {
    if (row.section == Section::Fluid) continue;
    EXPECT_EQ(value(q, row), value(p, row)) << row.name;
  }
}

// docs/scenes.md lists the table: one markdown table per section, rows as this test writes them.
std::string docs_rows(Section section) {
  std::string out;
  for (const Parameter& row : parameter_table()) {
    if (row.section != section) continue;
    out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", row.name, row.unit == "1" ? "—" : row.unit,
                       default_text(row), range_text(row), row.equation, row.meaning);
  }
  return out;
}

TEST(ParameterTable, DocsScenesListsEveryParameterAsTheTableHasIt) {
  std::ifstream in(std::string(OOBLECK_SOURCE_DIR) + "/docs/scenes.md");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const std::string docs = text.str();
  for (const Section s : {Section::Steady, Section::Granular, Section::Fluid}) {
    const std::string rows = docs_rows(s);
    EXPECT_NE(docs.find(rows), std::string::npos)
        << "docs/scenes.md: the [" << section_name(s) << "] rows differ from the parameter table; expected:\n"
        << rows;
  }
}

}  // namespace
