// The decomposition's layout (mpm/decomposition.hpp): which blocks, whose points, which
// neighbours, and what it refuses. The exchanges themselves run under mpirun in tests/mpi.
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/decomposition.hpp"

namespace oobleck::mpm {
namespace {

Grid<2> grid_2d() { return Grid<2>(Vec<2>(0.0, 0.0), 1e-3, {40, 20}, {true, false}); }
Grid<3> grid_3d() { return Grid<3>(Vec<3>(0.0, 0.0, 0.0), 1e-3, {4, 4, 20}, {true, true, false}); }

TEST(Decomposition, ChoosesTheSplitWithTheFewestGhostNodes) {
  // 40 x 20 cells on 2 ranks: a cut across the long axis is 20 nodes long, the other 40.
  EXPECT_EQ(Decomposition<2>(grid_2d(), 2, 0).dims_string(), "2x1");
  // 4 ranks: a block's cut faces are 20 nodes long (4x1), 10 + 20 (2x2) or 40 (1x4).
  EXPECT_EQ(Decomposition<2>(grid_2d(), 4, 0).dims_string(), "4x1");
  // 4 x 4 x 20 cells: only the long axis can be cut into blocks of at least 3 cells.
  EXPECT_EQ(Decomposition<3>(grid_3d(), 2, 0).dims_string(), "1x1x2");
  EXPECT_EQ(Decomposition<3>(grid_3d(), 6, 0).dims_string(), "1x1x6");
}

TEST(Decomposition, BlocksCoverEveryCellOnce) {
  const Grid<2> g = grid_2d();
  for (int ranks : {1, 2, 3, 5, 6}) {
    std::array<int, 2> dims{};
    if (ranks == 6) dims = {3, 2};
    std::vector<int> covered(static_cast<std::size_t>(g.cells[0] * g.cells[1]), 0);
    for (int r = 0; r < ranks; ++r) {
      const Decomposition<2> d(g, ranks, r, dims);
      const Grid<2> local = d.local_grid();
      EXPECT_DOUBLE_EQ(local.origin_m[0], d.block_begin(0) * g.h_m);
      EXPECT_EQ(local.periodic[0], !d.split(0));  // a split periodic axis is not periodic locally
      EXPECT_FALSE(local.periodic[1]);
      for (int i = 0; i < local.cells[0]; ++i)
        for (int j = 0; j < local.cells[1]; ++j)
          ++covered.at(static_cast<std::size_t>(d.block_begin(0) + i) * g.cells[1] + d.block_begin(1) + j);
    }
    for (int c : covered) ASSERT_EQ(c, 1) << ranks << " ranks";
  }
}

TEST(Decomposition, CutsBalanceTheLoad) {
  const Grid<2> g = grid_2d();  // 40 x 20 cells
  Decomposition<2>::Load load;
  load[0].assign(40, 0.0);
  load[1].assign(20, 0.0);
  for (int c = 0; c < 10; ++c) load[0][c] = 3.0;  // three quarters of the load in the first 10 cells
  for (int c = 10; c < 40; ++c) load[0][c] = 1.0 / 3.0;
  for (int c = 0; c < 8; ++c) load[1][c] = 1.0;  // a bed 8 cells deep under 12 empty ones
  const Decomposition<2> x(g, 2, 0, {2, 1}, load);
  // half of 40: cell 6 2/3 of the dense run; the nearer cell face is 7
  EXPECT_EQ(x.block_cells(0), 7);
  const Decomposition<2> y(g, 2, 0, {1, 2}, load);
  EXPECT_EQ(y.block_cells(1), 4);  // 4 + 4 layers of the bed
  const Decomposition<2> y3(g, 3, 0, {1, 3}, load);
  EXPECT_EQ(y3.block_cells(1), 3);  // 8/3 rounds to 3 = the fewest cells a block may have
  const Decomposition<2> y3_last(g, 3, 2, {1, 3}, load);
  EXPECT_EQ(y3_last.block_begin(1), 6);  // 16/3 = 5.3 → 5, kept 3 cells after the first cut
  // Without a load: equal shares of the cells.
  EXPECT_EQ(Decomposition<2>(g, 2, 0, {1, 2}).block_cells(1), 10);
}

TEST(Decomposition, OwnerOfAPositionIsTheBlockThatHoldsItsCell) {
  const Grid<2> g = grid_2d();
  const Decomposition<2> d(g, 6, 0, {3, 2});  // blocks of 13/13/14 x 10 cells
  for (int i = 0; i < g.cells[0]; ++i)
    for (int j = 0; j < g.cells[1]; ++j) {
      const Vec<2> x((i + 0.5) * g.h_m, (j + 0.5) * g.h_m);
      const int owner = d.owner(x);
      const Decomposition<2> od(g, 6, owner, {3, 2});
      EXPECT_GE(i, od.block_begin(0));
      EXPECT_LT(i, od.block_begin(0) + od.block_cells(0));
      EXPECT_GE(j, od.block_begin(1));
      EXPECT_LT(j, od.block_begin(1) + od.block_cells(1));
    }
  // Periodic x: beyond the end wraps to the first block; below 0 to the last. Non-periodic y:
  // outside the domain belongs to the end blocks.
  EXPECT_EQ(d.owner(Vec<2>(0.0405, 0.001)), d.owner(Vec<2>(0.0005, 0.001)));
  EXPECT_EQ(d.owner(Vec<2>(-0.0005, 0.001)), d.owner(Vec<2>(0.0395, 0.001)));
  EXPECT_EQ(d.owner(Vec<2>(0.001, -0.0005)), d.owner(Vec<2>(0.001, 0.0005)));
  EXPECT_EQ(d.owner(Vec<2>(0.001, 0.0205)), d.owner(Vec<2>(0.001, 0.0195)));
}

TEST(Decomposition, NeighboursWrapOnPeriodicAxesOnly) {
  const Grid<2> g = grid_2d();
  // Rank layout of 3x2 (row-major, as MPI_Cart_create): rank = 2 cx + cy.
  const Decomposition<2> first(g, 6, 0, {3, 2});  // (0, 0)
  EXPECT_EQ(first.neighbour(0, false), 4);        // (2, 0): across the periodic seam
  EXPECT_EQ(first.neighbour(0, true), 2);         // (1, 0)
  EXPECT_EQ(first.neighbour(1, false), -1);       // below: the wall
  EXPECT_EQ(first.neighbour(1, true), 1);         // (0, 1)
  const Decomposition<2> last(g, 6, 5, {3, 2});   // (2, 1)
  EXPECT_EQ(last.neighbour(0, true), 1);          // (0, 1)
  EXPECT_EQ(last.neighbour(1, true), -1);
  const Decomposition<2> unsplit(g, 2, 0, {1, 2});
  EXPECT_EQ(unsplit.neighbour(0, true), -1);  // not split: its own periodic local grid
}

TEST(Decomposition, RefusesLayoutsThatDoNotFit) {
  const Grid<3> g = grid_3d();
  auto message = [](auto&& make) {
    try {
      make();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] {
              Decomposition<3>(g, 2, 0, {3, 1, 1});
            }).find("3 ranks in the grid, but the run has 2"),
            std::string::npos);
  EXPECT_NE(message([&] {
              Decomposition<3>(g, 2, 0, {2, 1, 1});
            }).find("axis 0 has 4 cells, 2 per rank"),
            std::string::npos);
  EXPECT_NE(message([&] { Decomposition<3>(g, 7, 0); }).find("the grid (4x4x20 cells) is too small"),
            std::string::npos);
  EXPECT_NE(message([] { parse_ranks_grid<3>("2x1", "--ranks-grid"); }).find("expected 3 positive factors"),
            std::string::npos);
  EXPECT_NE(message([] { parse_ranks_grid<2>("2x0", "--ranks-grid"); }).find("expected 2 positive factors"),
            std::string::npos);
  EXPECT_NE(message([] { parse_ranks_grid<2>("2xa", "--ranks-grid"); }).find("expected 2"), std::string::npos);
  EXPECT_EQ(parse_ranks_grid<3>("1x2x3", "--ranks-grid"), (std::array<int, 3>{1, 2, 3}));
}

}  // namespace
}  // namespace oobleck::mpm
