// The registry's checkpoint loop (run/checkpoint_state.hpp): every kind of persistent field —
// a fixed array, a growing series, a real and an integer attribute, sampled node-field frames —
// written by save_fields and read back by restore_fields into a fresh owner, value for value;
// and the refusals: a missing array, frames that do not fit the grid, a second field whose
// frame count differs from the first's.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../cli/cli_runner.hpp"
#include "oobleck/analysis/fronts.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/run/checkpoint_state.hpp"
#include "oobleck/run/field_frames.hpp"

using namespace oobleck;

namespace {

/// An owner of one field of each kind, as an analysis would hold them.
struct Owner {
  std::vector<double> array = std::vector<double>(4, 0.0);
  std::vector<double> series;  // grows
  double real = 0.0;
  std::int64_t count = 0;
  std::vector<analysis::IntrusionFrame> frames;
  analysis::GridField2D shape;

  Owner() {
    shape.nx = 3;
    shape.ny = 2;
    shape.h = 0.5;
  }

  mpm::FieldList fields() {
    mpm::FieldList list;
    list.group("test");
    list.add_values("array", array, "m");
    list.add_series(
        "series", "s", [this] { return series; }, [this](const std::vector<double>& v) { series = v; });
    list.add_attribute("real", real, "Pa");
    list.add_attribute("count", count, "1");
    run::declare_field_frames(list, "frames", frames, shape, "m/s",
                              [](analysis::IntrusionFrame& f) -> analysis::GridField2D& { return f.field; });
    return list;
  }
};

std::string save(const clitest::TempDir& d, Owner& o, const std::string& name = "cp.h5") {
  std::string path = d / name;
  io::CheckpointWriter cp(path);
  cp.set_step(7);
  cp.set_time(0.25);
  cp.set_config("");
  run::save_fields(cp, o.fields(), [](const char* unit) { return std::string(unit); });
  cp.commit();
  return path;
}

}  // namespace

TEST(CheckpointState, EveryKindOfFieldRestoresValueForValue) {
  clitest::TempDir d;
  Owner a;
  a.array = {1.0, -2.5, 1e-300, 3.0};
  a.series = {0.1, 0.2, 0.30000000000000004};
  a.real = -1.0 / 3.0;
  a.count = 123456789012LL;
  for (int k = 0; k < 2; ++k) {
    analysis::IntrusionFrame fr;
    fr.time_s = 0.01 * (k + 1);
    fr.tip_z_m = -0.002 * k;
    fr.field = a.shape;
    for (int i = 0; i < 6; ++i) fr.field.values.push_back(k * 10.0 + i / 7.0);
    a.frames.push_back(fr);
  }
  const std::string path = save(d, a);

  Owner b;
  run::restore_fields(io::read_checkpoint(path), b.fields());
  EXPECT_EQ(b.array, a.array);
  EXPECT_EQ(b.series, a.series);
  EXPECT_EQ(b.real, a.real);
  EXPECT_EQ(b.count, a.count);
  ASSERT_EQ(b.frames.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(b.frames[k].time_s, a.frames[k].time_s);
    EXPECT_EQ(b.frames[k].tip_z_m, a.frames[k].tip_z_m);
    EXPECT_EQ(b.frames[k].field.values, a.frames[k].field.values);
    EXPECT_EQ(b.frames[k].field.nx, 3u);
    EXPECT_EQ(b.frames[k].field.h, 0.5);
  }
}

TEST(CheckpointState, EmptySeriesAreNotWrittenAndLeaveTheOwnerEmpty) {
  clitest::TempDir d;
  Owner a;  // nothing sampled yet
  const std::string path = save(d, a);
  const io::Checkpoint cp = io::read_checkpoint(path);
  EXPECT_TRUE(cp.has("test/array"));
  EXPECT_FALSE(cp.has("test/series"));
  EXPECT_FALSE(cp.has("test/frames/time"));
  Owner b;
  b.series = {9.0};  // replaced only by a stored series
  run::restore_fields(cp, b.fields());
  EXPECT_EQ(b.series, std::vector<double>{9.0});
  EXPECT_TRUE(b.frames.empty());
}

TEST(CheckpointState, RefusesMissingArraysAndFramesOfAnotherGrid) {
  clitest::TempDir d;
  Owner a;
  analysis::IntrusionFrame fr;
  fr.field = a.shape;
  fr.field.values.assign(6, 1.0);
  a.frames.push_back(fr);
  const std::string path = save(d, a);
  const io::Checkpoint cp = io::read_checkpoint(path);

  Owner other_grid;  // the same fields on a 4 × 2 grid: 6 stored values do not fill a frame of 8
  other_grid.shape.nx = 4;
  try {
    run::restore_fields(cp, other_grid.fields());
    ADD_FAILURE() << "frames of another grid accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("'test/frames/values'"), std::string::npos) << what;
  }

  Owner longer;  // one more array than the checkpoint has
  mpm::FieldList list = longer.fields();
  std::vector<double> extra(2, 0.0);
  list.add_values("extra", extra, "1");
  try {
    run::restore_fields(cp, list);
    ADD_FAILURE() << "missing array accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test/extra"), std::string::npos) << e.what();
  }

  // A second field of the same frames (as the annular analysis's f beside v_theta) must have
  // as many frames as the first.
  Owner two;
  mpm::FieldList second = two.fields();
  std::vector<analysis::IntrusionFrame> none;
  run::declare_field_frames(
      second, "frames", none, two.shape, "1",
      [](analysis::IntrusionFrame& f) -> analysis::GridField2D& { return f.field; }, false);
  EXPECT_THROW(run::restore_fields(cp, second), InputError);
}
