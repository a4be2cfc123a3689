// Rheometer export readers (src/oobleck/io/rheometer.hpp). The fixtures in
// tests/rheology/data/rheometer were written by make_fixtures.py from hermes2016 flow curves, one
// per format, printed to 5 significant digits in the instruments' units; truth.csv holds the same
// values in SI at full precision. Each reader must give them back within the printed precision
// (relative 5e-5), and every bad input must be an InputError naming the file, line and rule.
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io_test_util.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/rheometer.hpp"

namespace oobleck::io {
namespace {

using test::TempDir;
using ::testing::HasSubstr;

const std::string kDir = std::string(OOBLECK_SOURCE_DIR) + "/tests/rheology/data/rheometer/";
constexpr double kPrinted = 5e-5;  // half a unit in the 5th significant digit, relative

struct TruthRow {
  std::string file, step;
  double time, shear_rate, shear_stress, viscosity, strain;
};

/// truth.csv: file,step_name and five numbers (no quotes, no commas inside fields).
std::vector<TruthRow> truth() {
  std::ifstream in(kDir + "truth.csv");
  std::vector<TruthRow> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    rows.push_back({f.at(0), f.at(1), std::stod(f.at(2)), std::stod(f.at(3)), std::stod(f.at(4)), std::stod(f.at(5)),
                    std::stod(f.at(6))});
  }
  return rows;
}

std::string write(const TempDir& dir, const std::string& name, const std::string& content) {
  std::string path = dir.file(name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

void expect_close(double got, double want, const std::string& what) {
  EXPECT_LE(std::abs(got - want), kPrinted * std::abs(want) + 1e-300) << what << ": got " << got << ", want " << want;
}

struct Case {
  const char* file;
  RheometerFormat format;
  const char* encoding;
  char separator, decimal;
};

class RoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(RoundTrip, ReadsBackTheValuesTheFixtureWasWrittenFromWithinItsPrintedPrecision) {
  const Case c = GetParam();
  const RheometerFile f = read_rheometer(kDir + c.file);
  EXPECT_EQ(f.format, c.format);
  EXPECT_EQ(f.encoding, c.encoding);
  EXPECT_EQ(f.separator, c.separator);
  EXPECT_EQ(f.decimal, c.decimal);
  std::map<std::string, std::size_t> next_row;  // step name -> rows compared
  std::size_t compared = 0;
  for (const auto& t : truth()) {
    if (t.file != c.file) continue;
    const RheometerStep* step = nullptr;
    for (const auto& s : f.steps) {
      if (s.name == t.step) step = &s;
    }
    ASSERT_NE(step, nullptr) << c.file << ": no step '" << t.step << "'";
    const std::size_t i = next_row[t.step]++;
    ASSERT_LT(i, step->rows());
    const std::string where = std::string(c.file) + " step '" + t.step + "' row " + std::to_string(i + 1);
    expect_close(step->find("time")->values[i], t.time, where + " time [s]");
    expect_close(step->find("shear_rate")->values[i], t.shear_rate, where + " shear_rate [1/s]");
    expect_close(step->find("shear_stress")->values[i], t.shear_stress, where + " shear_stress [Pa]");
    expect_close(step->find("viscosity")->values[i], t.viscosity, where + " viscosity [Pa s]");
    if (const auto* strain = step->find("strain")) expect_close(strain->values[i], t.strain, where + " strain [-]");
    ++compared;
  }
  for (const auto& [name, n] : next_row) {
    for (const auto& s : f.steps) {
      if (s.name == name) {
        EXPECT_EQ(s.rows(), n) << c.file << " step '" << name << "': rows not in truth.csv";
      }
    }
  }
  EXPECT_GE(compared, 16u);
}

INSTANTIATE_TEST_SUITE_P(Fixtures, RoundTrip,
                         ::testing::Values(Case{"trios_phi040.txt", RheometerFormat::trios, "UTF-8", '\t', '.'},
                                           Case{"rheocompass_phi044.csv", RheometerFormat::rheocompass, "UTF-16LE", ';',
                                                ','},
                                           Case{"rspace_phi046.csv", RheometerFormat::rspace, "UTF-8", ';', ','},
                                           Case{"generic_phi048.csv", RheometerFormat::csv, "UTF-8", ',', '.'}),
                         [](const auto& test_info) {
                           const std::string f = test_info.param.file;
                           return f.substr(0, f.find('_'));
                         });

TEST(Rheometer, TriosStepsAttributesAndUnits) {
  const RheometerFile f = read_rheometer(kDir + "trios_phi040.txt");
  ASSERT_EQ(f.steps.size(), 2u);
  EXPECT_EQ(f.steps[0].name, "Peak hold - 1");
  EXPECT_EQ(f.steps[1].name, "Flow sweep - 2");
  EXPECT_EQ(f.steps[1].index, 2);
  EXPECT_EQ(f.attributes.at("sample"), "cornstarch phi 0.40 (synthetic, hermes2016)");
  EXPECT_EQ(f.attributes.at("geometry"), "40 mm parallel plate, 1000 um gap");
  EXPECT_EQ(f.attributes.at("date"), "14/03/2024");
  EXPECT_EQ(f.attributes.at("procedure_steps"), "Peak hold#Flow sweep");
  EXPECT_EQ(f.attributes.at("Geometry Parameters/Geometry Type"), "Parallel plate");
  EXPECT_EQ(f.attributes.at("Geometry Parameters/Inertia"), "12.3 \u00b5N.m.s\u00b2");
  const auto& sweep = f.steps[1];
  EXPECT_EQ(sweep.find("viscosity")->unit, "mPa.s");
  EXPECT_EQ(sweep.find("viscosity")->si_unit, "Pa s");
  EXPECT_EQ(sweep.find("shear_stress")->header, "Stress");
  EXPECT_EQ(sweep.find("strain")->unit, "%");
  EXPECT_EQ(sweep.find("temperature")->si_unit, "\u00b0C");
  EXPECT_DOUBLE_EQ(sweep.find("temperature")->values[0], 25.0);
  // Torque in uN.m: 1.3825e-2 uN.m in the first row.
  EXPECT_EQ(sweep.find("torque")->si_unit, "N m");
  EXPECT_NEAR(sweep.find("torque")->values[0], 1.3825e-8, 1e-14);
  EXPECT_NE(sweep.find("step_time"), nullptr);
  EXPECT_EQ(sweep.lines[0], 37);  // the first data row of "Flow sweep - 2"
}

TEST(Rheometer, RheocompassIntervalsTextAndMissingValues) {
  const RheometerFile f = read_rheometer(kDir + "rheocompass_phi044.csv");
  EXPECT_EQ(f.attributes.at("project"), "Cornstarch");
  EXPECT_EQ(f.attributes.at("sample"), "cornstarch phi 0.44 (synthetic, hermes2016)");
  ASSERT_EQ(f.steps.size(), 2u);
  EXPECT_EQ(f.steps[0].name, "Flow curve 1 - 1");
  EXPECT_EQ(f.steps[1].name, "Flow curve 1 - 2");
  const auto* status = f.steps[0].find("status");
  ASSERT_NE(status, nullptr);
  EXPECT_TRUE(status->is_text);
  EXPECT_EQ(status->text[1], "WMa,TruStrain\u2122");  // quoted, with the separator of a comma CSV inside
  EXPECT_TRUE(std::isnan(f.steps[0].find("torque")->values[1]));
  EXPECT_NEAR(f.steps[0].find("torque")->values[0], 0.0034738e-3, 1e-12);
  EXPECT_EQ(f.steps[0].find("point")->values[2], 3.0);
  EXPECT_EQ(f.steps[1].find("viscosity")->unit, "mPa\u00b7s");
}

TEST(Rheometer, RspaceActionsAndEmptyColumns) {
  const RheometerFile f = read_rheometer(kDir + "rspace_phi046.csv");
  ASSERT_EQ(f.steps.size(), 2u);
  EXPECT_EQ(f.steps[0].name, "Equilibration");
  EXPECT_TRUE(std::isnan(f.steps[0].find("shear_rate")->values[0]));
  EXPECT_DOUBLE_EQ(f.steps[0].find("gap")->values[0], 1e-3);
  EXPECT_EQ(f.steps[1].find("shear_rate")->unit, "s-\u00b9");
  EXPECT_EQ(f.steps[1].find("shear_stress")->unit, "kPa");
  EXPECT_NE(f.steps[1].find("step_time"), nullptr);  // Time (action)
  // The default flow-curve step is the one with both values.
  const auto rows = flow_curve_rows(f, "");
  EXPECT_EQ(rows.steps, std::vector<std::size_t>{1});
  EXPECT_EQ(rows.shear_rate.size(), f.steps[1].rows());
}

TEST(Rheometer, StepSelectionByIndexAndNameIgnoresCaseAndTheIndexSuffix) {
  const RheometerFile f = read_rheometer(kDir + "trios_phi040.txt");
  EXPECT_EQ(select_steps(f, "Flow sweep"), std::vector<std::size_t>{1});
  EXPECT_EQ(select_steps(f, "flow SWEEP"), std::vector<std::size_t>{1});
  EXPECT_EQ(select_steps(f, "Flow sweep - 2"), std::vector<std::size_t>{1});
  EXPECT_EQ(select_steps(f, "1"), std::vector<std::size_t>{0});
  EXPECT_THAT(error_of([&] { (void)select_steps(f, "Flow sweeps"); }),
              AllOf(HasSubstr("--step = 'Flow sweeps': no such step"), HasSubstr("did you mean"),
                    HasSubstr("1 'Peak hold - 1', 2 'Flow sweep - 2'")));
  EXPECT_THAT(error_of([&] { (void)select_steps(f, "3"); }), HasSubstr("--step = 3: "));
  // Two steps with rate and stress: the fit must be told which.
  EXPECT_THAT(
      error_of([&] { (void)flow_curve_rows(f, ""); }),
      AllOf(HasSubstr("2 steps hold shear rate and stress"), HasSubstr("choose one with --step NAME or INDEX")));
  const auto rows = flow_curve_rows(f, "flow sweep");
  EXPECT_EQ(rows.shear_rate.size(), 16u);
  // Several intervals of one result share the name without the suffix.
  const RheometerFile rc = read_rheometer(kDir + "rheocompass_phi044.csv");
  EXPECT_EQ(select_steps(rc, "flow curve 1"), (std::vector<std::size_t>{0, 1}));
}

TEST(Rheometer, TableHasTheCoreColumnsFirstAndEveryOtherColumnOnce) {
  const RheometerFile f = read_rheometer(kDir + "trios_phi040.txt");
  const RheometerTable t = to_table(f);
  EXPECT_EQ(t.rows, 20u);
  std::vector<std::string> names;
  for (const auto& c : t.columns) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"step", "step_name", "time", "shear_rate", "shear_stress", "viscosity",
                                             "step_time", "temperature", "strain", "torque", "status"}));
  EXPECT_EQ(t.columns[1].text[0], "Peak hold - 1");
  EXPECT_EQ(t.columns[1].text[19], "Flow sweep - 2");
  EXPECT_EQ(t.columns[0].values[19], 2.0);
  EXPECT_EQ(t.columns[5].units_read, "Pa.s, mPa.s");
  EXPECT_TRUE(std::isnan(t.columns[8].values[0]));  // the peak hold has no strain column
}

TEST(Rheometer, GenericCsvDetectsSeparatorDecimalCommaAndUnitSpellings) {
  TempDir dir;
  const auto p = write(dir, "semi.csv",
                       "Shear rate (1/s);Shear stress [Pa];Viscosity [mPas];Temperature [\xc2\xb0"
                       "C]\n"
                       "0,5;1,25;2500;20,5\n"
                       "1,0E+001;2,5e1;2500;20,5\n");
  const RheometerFile f = read_rheometer(p);
  EXPECT_EQ(f.separator, ';');
  EXPECT_EQ(f.decimal, ',');
  ASSERT_EQ(f.steps.size(), 1u);
  EXPECT_EQ(f.steps[0].name, "semi");
  EXPECT_DOUBLE_EQ(f.steps[0].find("shear_rate")->values[1], 10.0);
  EXPECT_DOUBLE_EQ(f.steps[0].find("viscosity")->values[0], 2.5);
  const auto tab = write(dir, "tab.txt", "shear_rate [s\xe2\x81\xbb\xc2\xb9]\tshear_stress [kPa]\n2\t0,003\n");
  const RheometerFile g = read_rheometer(tab);
  EXPECT_EQ(g.separator, '\t');
  EXPECT_DOUBLE_EQ(g.steps[0].find("shear_stress")->values[0], 3.0);
  // Latin-1 (no valid UTF-8): the degree sign of °C.
  const auto latin = write(dir, "latin.csv",
                           "shear_rate [1/s],T [\xb0"
                           "C]\n1,20\n");
  const RheometerFile l = read_rheometer(latin);
  EXPECT_EQ(l.encoding, "WINDOWS-1252");
  EXPECT_EQ(l.steps[0].find("t")->unit, "\u00b0C");
  // The file `oobleck rheology import` writes: steps come back from step/step_name.
  const auto own = write(dir, "own.csv",
                         "step,step_name,time,shear_rate,shear_stress,viscosity\n"
                         "1,Peak hold - 1,1,1,2,2\n2,Flow sweep - 2,3,4,5,1.25\n2,Flow sweep - 2,4,5,6,1.2\n");
  const RheometerFile o = read_rheometer(own);
  ASSERT_EQ(o.steps.size(), 2u);
  EXPECT_EQ(o.steps[1].name, "Flow sweep - 2");
  EXPECT_EQ(o.steps[1].rows(), 2u);
  EXPECT_EQ(o.steps[1].find("step"), nullptr);
}

TEST(Rheometer, BadInputNamesFileLineAndWhatWasExpected) {
  TempDir dir;
  auto err = [&](const std::string& name, const std::string& content,
                 RheometerFormat fmt = RheometerFormat::automatic) {
    const auto p = write(dir, name, content);
    return error_of([&] { (void)read_rheometer(p, fmt); });
  };
  EXPECT_THAT(
      err("unit.csv", "shear_rate [1/s];viscosity [mPa-s]\n1;2\n"),
      AllOf(HasSubstr("unit.csv:1: column 'viscosity': unknown unit 'mPa-s'; expected one of"), HasSubstr("mPa s")));
  EXPECT_THAT(err("kind.csv", "shear_rate [Pa],shear_stress [Pa]\n1,2\n"),
              HasSubstr("kind.csv:1: column 'shear_rate' is shear_rate but its unit 'Pa' is not one of 1/s"));
  EXPECT_THAT(err("num.csv", "shear_rate [1/s],shear_stress [Pa]\n1,2\n3,abc\n"),
              HasSubstr("num.csv:3: column 'shear_stress': 'abc' is not a finite number"));
  EXPECT_THAT(err("short.csv", "a,b,c\n1,2\n"), HasSubstr("short.csv:2: 2 values but the header (line 1) has 3"));
  EXPECT_THAT(err("long.csv", "a,b\n1,2,3\n"), HasSubstr("long.csv:2: 3 values but 2 column names"));
  EXPECT_THAT(err("nothing.txt", "just one line of prose\n"),
              AllOf(HasSubstr("nothing.txt:1: 'just one line of prose' fits no format: expected a TRIOS export"),
                    HasSubstr("RheoCompass"), HasSubstr("rSpace")));
  EXPECT_THAT(err("empty.csv", ""), HasSubstr("empty.csv: no header row"));
  EXPECT_THAT(err("nodata.csv", "a,b\n"), HasSubstr("nodata.csv: no data rows"));
  EXPECT_THAT(err("trios.txt", "Filename\tx.tri\n\n[step]\nFlow sweep - 1\nTime\tStress\n1\t2\n"),
              HasSubstr("trios.txt:6: step 'Flow sweep - 1': '1' is a number: expected the line of units"));
  EXPECT_THAT(err("trios2.txt", "Filename\tx.tri\n\n[step]\nFlow sweep - 1\nTime\tShear rate\ns\t\n1\t2\n"),
              HasSubstr("trios2.txt:6: column 'Shear rate' has no unit: expected its unit (1/s)"));
  EXPECT_THAT(err("forced.csv", "a,b\n1,2\n", RheometerFormat::trios),
              HasSubstr("forced.csv: no [step] section: expected a TA TRIOS 'Export to LIMS' file"));
  EXPECT_THAT(err("rc.csv", "Project:;P\nResult:;R\nInterval data:;Time;Shear Rate\n;1;2\n"),
              HasSubstr("rc.csv:4: interval 'R - 1': expected the line of units in brackets"));
  EXPECT_THAT(err("rs.csv", "Action Name;Shear rate(s-1)\n;1\n"), HasSubstr("rs.csv:2: empty action name"));
  EXPECT_THAT(error_of([] { (void)read_rheometer("/nonexistent/x.txt"); }),
              HasSubstr("/nonexistent/x.txt: cannot open data file"));
  EXPECT_THAT(error_of([] { (void)parse_rheometer_format("lims", "format"); }),
              HasSubstr("format = 'lims': must be one of auto, trios, rheocompass"));
  // Non-positive values in a flow curve name the line.
  const auto p = write(dir, "zero.csv", "shear_rate,shear_stress\n1,2\n0,3\n");
  const RheometerFile f = read_rheometer(p);
  EXPECT_THAT(error_of([&] { (void)flow_curve_rows(f, ""); }),
              HasSubstr("zero.csv:3: step 'zero': shear rate 0 1/s, shear stress 3 Pa"));
}

}  // namespace
}  // namespace oobleck::io
