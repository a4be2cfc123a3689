// CSV time series (header, rows flushed as written, resume after restart) and summary.json.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io_test_util.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/series.hpp"
#include "oobleck/io/summary.hpp"

namespace fs = std::filesystem;
using namespace oobleck;
using namespace oobleck::io;
using oobleck::test::read_text;
using oobleck::test::TempDir;

TEST(Series, HeaderAndRowsAreOnDiskAfterEachRow) {
  TempDir dir;
  const std::string path = dir.file("series.csv");
  SeriesWriter s(path, {"step", "time", "kinetic_energy_grains", "max_speed"});
  EXPECT_EQ(read_text(path), "step,time,kinetic_energy_grains,max_speed\n");
  s.row({0, 0.0, 0.0, 0.0});
  // Visible to another reader before the writer closes: flushed per row.
  EXPECT_EQ(read_text(path), "step,time,kinetic_energy_grains,max_speed\n0,0,0,0\n");
  const double third = 1.0 / 3.0;
  s.row({10, 1e-5, third, -2.5e-12});
  const std::vector<double> v{20, 2e-5, std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::infinity()};
  s.row(v);
  EXPECT_EQ(s.rows_written(), 3u);
  EXPECT_EQ(read_text(path),
            "step,time,kinetic_energy_grains,max_speed\n"
            "0,0,0,0\n"
            "10,1e-05,0.3333333333333333,-2.5e-12\n"
            "20,2e-05,nan,inf\n");
  // Shortest round-trip form: reads back to the same double.
  EXPECT_EQ(std::stod("0.3333333333333333"), third);
}

TEST(Series, RowOfWrongLengthAndBadColumnsAreRefused) {
  TempDir dir;
  SeriesWriter s(dir.file("s.csv"), {"a", "b"});
  EXPECT_THROW(s.row({1.0}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a", "a"}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a,b"}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("missing/t.csv"), {"a"}), InputError);
}

TEST(Series, ResumeDropsRowsAfterTheRestartPoint) {
  TempDir dir;
  const std::string path = dir.file("series.csv");
  {
    SeriesWriter s(path, {"step", "e"});
    for (int k = 0; k < 5; ++k) s.row({10.0 * k, 0.5 * k});
  }
  {
    SeriesWriter s = SeriesWriter::resume(path, {"step", "e"}, 20);
    EXPECT_EQ(s.rows_written(), 3u);
    s.row({25, 9});
  }
  EXPECT_EQ(read_text(path), "step,e\n0,0\n10,0.5\n20,1\n25,9\n");
  EXPECT_THROW(SeriesWriter::resume(path, {"step", "energy"}, 20), InputError);
  // A row cut by a kill (no line break) is dropped; a malformed complete row is an error.
  std::ofstream(path, std::ios::app) << "30,1.2";
  {
    SeriesWriter s = SeriesWriter::resume(path, {"step", "e"}, 100);
    EXPECT_EQ(s.rows_written(), 4u);
  }
  EXPECT_EQ(read_text(path), "step,e\n0,0\n10,0.5\n20,1\n25,9\n");
  std::ofstream(path, std::ios::app) << "30\n";
  EXPECT_THROW(SeriesWriter::resume(path, {"step", "e"}, 100), InputError);
  EXPECT_THROW(SeriesWriter::resume(dir.file("none.csv"), {"step"}, 20), InputError);
}

TEST(Series, UnitsLineComesFirstAndNamesEveryColumn) {
  TempDir dir;
  const std::string path = dir.file("series.csv");
  {
    SeriesWriter s(path, {"time", "step", "mass_grains"}, {"s", "1", "kg/rad"});
    s.row({0.0, 0, 1.5});
    s.row({1e-3, 10, 1.5});
  }
  EXPECT_EQ(read_text(path),
            "# units: time=s, step=1, mass_grains=kg/rad\ntime,step,mass_grains\n0,0,1.5\n0.001,10,1.5\n");
  {  // a restart keeps the rows up to its time and writes the units line once
    SeriesWriter s = SeriesWriter::resume(path, {"time", "step", "mass_grains"}, 0.0, {"s", "1", "kg/rad"});
    EXPECT_EQ(s.rows_written(), 1u);
  }
  EXPECT_EQ(read_text(path), "# units: time=s, step=1, mass_grains=kg/rad\ntime,step,mass_grains\n0,0,1.5\n");
  // A series written without units (an older run) resumes with them.
  std::ofstream(path, std::ios::trunc) << "time,step,mass_grains\n0,0,1.5\n0.001,10,1.5\n";
  {
    SeriesWriter s = SeriesWriter::resume(path, {"time", "step", "mass_grains"}, 1.0, {"s", "1", "kg/rad"});
    EXPECT_EQ(s.rows_written(), 2u);
  }
  EXPECT_EQ(read_text(path),
            "# units: time=s, step=1, mass_grains=kg/rad\ntime,step,mass_grains\n0,0,1.5\n0.001,10,1.5\n");
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a", "b"}, {"s"}), std::invalid_argument);  // one per column
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a"}, {""}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a"}, {"m,s"}), std::invalid_argument);
  EXPECT_THROW(SeriesWriter(dir.file("t.csv"), {"a"}, {"a=b"}), std::invalid_argument);
}

TEST(Summary, WritesJsonAtomically) {
  TempDir dir;
  nlohmann::json j;
  j["points"] = 12000;
  j["steps"] = 1000;
  j["wall_seconds"] = 1.5;
  j["point_updates_per_second"] = 8e6;
  j["threads"] = 2;
  j["settling_velocity"] = std::numeric_limits<double>::quiet_NaN();
  j["parameters"] = {{"phi", 0.47}, {"rho_s", 1620.0}};
  const std::string path = write_summary(dir.str(), j);
  EXPECT_EQ(path, dir.file("summary.json"));
  const auto back = nlohmann::json::parse(read_text(path));
  EXPECT_EQ(back["points"], 12000);
  EXPECT_EQ(back["parameters"]["phi"], 0.47);
  EXPECT_TRUE(back["settling_velocity"].is_null());  // JSON has no NaN
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.str())) ++files;
  EXPECT_EQ(files, 1u);  // no temporary left
  EXPECT_THROW(write_summary(dir.file("missing"), j), InputError);
}
