// HDF5 frames + XDMF index: exact round trip through the HDF5 C API, index consistency,
// resume after restart, input checks.
#include <array>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>

#include <gtest/gtest.h>

#include "io_test_util.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/frames.hpp"

namespace fs = std::filesystem;
using namespace oobleck;
using namespace oobleck::io;
using oobleck::test::read_h5_attr;
using oobleck::test::read_h5_doubles;
using oobleck::test::read_text;
using oobleck::test::TempDir;

namespace {

std::vector<double> ramp(std::size_t n, double start, double step = 1.0) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = start + step * static_cast<double>(i) + 1.0 / 3.0;
  return v;
}

/// Every HDF reference of the index: (dimensions, "file:/dataset").
std::vector<std::pair<std::vector<std::uint64_t>, std::string>> hdf_refs(const std::string& xmf) {
  std::vector<std::pair<std::vector<std::uint64_t>, std::string>> out;
  const std::string text = read_text(xmf);
  const std::regex item(R"re(<DataItem Dimensions="([0-9 ]+)"[^>]*Format="HDF">([^<]+)</DataItem>)re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), item); it != std::sregex_iterator(); ++it) {
    std::vector<std::uint64_t> dims;
    std::istringstream ss((*it)[1].str());
    for (std::uint64_t d; ss >> d;) dims.push_back(d);
    out.emplace_back(dims, (*it)[2].str());
  }
  return out;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// Exit status of tools/check_xdmf.py on `xmf` (-1 without python3); `no_h5py` forces the
/// checks that do without h5py.
int run_checker(const std::string& xmf, bool no_h5py = false) {
  if (!fs::exists("/usr/bin/python3")) return -1;
  const std::string cmd = std::string(no_h5py ? "CHECK_XDMF_NO_H5PY=1 " : "") + "/usr/bin/python3 " +
                          std::string(OOBLECK_SOURCE_DIR) + "/tools/check_xdmf.py --quiet '" + xmf + "'";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
}

}  // namespace

TEST(Frames, RoundTrip2DBodiesAndGridExactly) {
  TempDir dir;
  const std::size_t n = 5;
  const auto pos = ramp(2 * n, 0.1, 0.01);  // interleaved x y
  const auto p = ramp(n, 100.0, -7.5);
  const auto v2 = ramp(2 * n, -1.0, 0.25);  // 2-component vector, interleaved
  std::vector<std::vector<double>> s(6);
  for (std::size_t c = 0; c < 6; ++c) s[c] = ramp(n, 10.0 * static_cast<double>(c));
  const auto L = ramp(9 * n, 3.0, 1e-3);
  // A second body given as structure of arrays, with a 3-component (swirl) velocity.
  const auto fx = ramp(3, 1.0), fy = ramp(3, 2.0), u = ramp(3, 5.0), w = ramp(3, 6.0), th = ramp(3, 7.0);

  PointCloud grains("grains", 2, pos);
  grains.scalar("pressure", p, "Pa")
      .vector("velocity", 2, v2, "m/s")
      .sym_tensor("stress", {s[0], s[1], s[2], s[3], s[4], s[5]}, "Pa");
  grains.tensor("velocity_gradient", L, "1/s");
  PointCloud fluid("fluid", {fx, fy});
  fluid.vector("velocity", {u, w, th}, "m/s");

  NodeGrid grid(2, {0.5, -1.0, 0.0}, {0.25, 0.5, 0.0}, {4, 3, 1});
  const auto mass = ramp(12, 0.0, 0.5);
  const auto gv = ramp(24, 1.0, -0.125);
  grid.scalar("mass", mass, "kg/m").vector("velocity", 2, gv, "m/s");

  FrameWriter writer(dir.str());
  Frame f0{0.0, 0, {grains, fluid}, grid};
  const std::string path0 = writer.write(f0);
  Frame f1{2.5e-4, 250, {grains}, std::nullopt};
  const std::string path1 = writer.write(f1);
  EXPECT_EQ(writer.frames_written(), 2u);
  EXPECT_EQ(path0, dir.file("frames/frame_000000.h5"));
  EXPECT_EQ(path1, dir.file("frames/frame_000001.h5"));
  EXPECT_TRUE(fs::exists(dir.file("frames.xmf")));

  double t = -1, step = -1;
  ASSERT_TRUE(read_h5_attr(path1, "/", "time", t));
  ASSERT_TRUE(read_h5_attr(path1, "/", "step", step));
  EXPECT_EQ(t, 2.5e-4);
  EXPECT_EQ(step, 250.0);

  auto rp = read_h5_doubles(path0, "/bodies/grains/position");
  ASSERT_TRUE(rp.ok);
  EXPECT_EQ(rp.shape, (std::vector<std::uint64_t>{n, 2}));
  EXPECT_EQ(rp.values, pos);

  auto rs = read_h5_doubles(path0, "/bodies/grains/pressure");
  EXPECT_EQ(rs.shape, (std::vector<std::uint64_t>{n}));
  EXPECT_EQ(rs.values, p);

  auto rv = read_h5_doubles(path0, "/bodies/grains/velocity");
  ASSERT_EQ(rv.shape, (std::vector<std::uint64_t>{n, 3}));  // padded to 3 components
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(rv.values[3 * i], v2[2 * i]);
    EXPECT_EQ(rv.values[3 * i + 1], v2[2 * i + 1]);
    EXPECT_EQ(rv.values[3 * i + 2], 0.0);
  }

  auto rt = read_h5_doubles(path0, "/bodies/grains/stress");
  ASSERT_EQ(rt.shape, (std::vector<std::uint64_t>{n, 6}));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < 6; ++c) EXPECT_EQ(rt.values[6 * i + c], s[c][i]);

  auto rl = read_h5_doubles(path0, "/bodies/grains/velocity_gradient");
  EXPECT_EQ(rl.shape, (std::vector<std::uint64_t>{n, 9}));
  EXPECT_EQ(rl.values, L);

  auto rfp = read_h5_doubles(path0, "/bodies/fluid/position");
  ASSERT_EQ(rfp.shape, (std::vector<std::uint64_t>{3, 2}));
  auto rfv = read_h5_doubles(path0, "/bodies/fluid/velocity");
  ASSERT_EQ(rfv.shape, (std::vector<std::uint64_t>{3, 3}));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(rfp.values[2 * i], fx[i]);
    EXPECT_EQ(rfp.values[2 * i + 1], fy[i]);
    EXPECT_EQ(rfv.values[3 * i], u[i]);
    EXPECT_EQ(rfv.values[3 * i + 1], w[i]);
    EXPECT_EQ(rfv.values[3 * i + 2], th[i]);
  }

  auto rm = read_h5_doubles(path0, "/grid/mass");
  EXPECT_EQ(rm.shape, (std::vector<std::uint64_t>{1, 3, 4}));  // (nz, ny, nx), x fastest
  EXPECT_EQ(rm.values, mass);
  auto rgv = read_h5_doubles(path0, "/grid/velocity");
  ASSERT_EQ(rgv.shape, (std::vector<std::uint64_t>{1, 3, 4, 3}));
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(rgv.values[3 * i], gv[2 * i]);
    EXPECT_EQ(rgv.values[3 * i + 1], gv[2 * i + 1]);
    EXPECT_EQ(rgv.values[3 * i + 2], 0.0);
  }
  // Frame 1 has no grid and no fluid.
  EXPECT_FALSE(read_h5_doubles(path1, "/grid/mass").ok);
  EXPECT_FALSE(read_h5_doubles(path1, "/bodies/fluid/position").ok);
  EXPECT_EQ(read_h5_doubles(path1, "/bodies/grains/position").values, pos);
}

TEST(Frames, EveryDatasetCarriesItsUnits) {
  TempDir dir;
  const auto pos = ramp(6, 0.0), p = ramp(3, 1.0), v = ramp(6, 2.0), t6 = ramp(18, 3.0);
  PointCloud grains("grains", 2, pos);
  grains.scalar("mass", p, "kg/rad").vector("velocity", 2, v, "m/s").sym_tensor("stress", t6, "Pa");
  PointCloud rod("rod", 2, pos, "mm");  // positions in other units than metres
  rod.scalar("f", p, "1");
  NodeGrid grid(2, {0, 0, 0}, {1, 1, 0}, {3, 2, 1});
  const auto porosity = ramp(6, 0.5);  // a field is a view: its values must outlive the write
  grid.scalar("porosity", porosity, "1");
  FrameWriter writer(dir.str());
  const std::string path = writer.write({0.0, 0, {grains, rod}, grid});
  const std::map<std::string, std::string> expected = {{"/bodies/grains/position", "m"},
                                                       {"/bodies/grains/connectivity", "1"},
                                                       {"/bodies/grains/mass", "kg/rad"},
                                                       {"/bodies/grains/velocity", "m/s"},
                                                       {"/bodies/grains/stress", "Pa"},
                                                       {"/bodies/rod/position", "mm"},
                                                       {"/bodies/rod/connectivity", "1"},
                                                       {"/bodies/rod/f", "1"},
                                                       {"/grid/porosity", "1"}};
  const std::vector<std::string> datasets = oobleck::test::h5_datasets(path);
  EXPECT_EQ(datasets.size(), expected.size());
  for (const std::string& d : datasets) {
    std::string units;
    EXPECT_TRUE(oobleck::test::read_h5_text_attr(path, d, "units", units)) << d << " has no units";
    ASSERT_TRUE(expected.count(d) == 1) << d;
    EXPECT_EQ(units, expected.at(d)) << d;
  }
  EXPECT_EQ(run_checker(dir.file("frames.xmf")), 0);  // (the index is unchanged by the attributes)
}

TEST(Frames, Grid3DNodeOrderingIsXFastest) {
  TempDir dir;
  const std::size_t nx = 3, ny = 2, nz = 2, nn = nx * ny * nz;
  std::vector<double> id(nn), vx(nn), vy(nn), vz(nn);
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t a = i + nx * (j + ny * k);
        id[a] = static_cast<double>(100 * k + 10 * j + i);
        vx[a] = static_cast<double>(i);
        vy[a] = static_cast<double>(j);
        vz[a] = static_cast<double>(k);
      }
  NodeGrid grid(3, {0, 0, 0}, {0.1, 0.2, 0.3}, {nx, ny, nz});
  grid.scalar("id", id, "1").vector("velocity", {vx, vy, vz}, "m/s");
  const auto pos = ramp(3 * 4, 0.0, 0.1);
  PointCloud solid("solid", 3, pos);
  FrameWriter writer(dir.str(), "run");
  const std::string path = writer.write({1.0, 7, {solid}, grid});
  EXPECT_EQ(writer.index_path(), dir.file("run.xmf"));
  auto r = read_h5_doubles(path, "/grid/id");
  ASSERT_EQ(r.shape, (std::vector<std::uint64_t>{nz, ny, nx}));
  // C order: element [k][j][i] at (k*ny + j)*nx + i.
  EXPECT_EQ(r.values[(1 * ny + 1) * nx + 2], 112.0);
  auto v = read_h5_doubles(path, "/grid/velocity");
  ASSERT_EQ(v.shape, (std::vector<std::uint64_t>{nz, ny, nx, 3}));
  const std::size_t a = (1 * ny + 0) * nx + 2;
  EXPECT_EQ(v.values[3 * a], 2.0);
  EXPECT_EQ(v.values[3 * a + 1], 0.0);
  EXPECT_EQ(v.values[3 * a + 2], 1.0);
  const std::string xmf = read_text(writer.index_path());
  EXPECT_NE(xmf.find(R"(TopologyType="3DCoRectMesh" Dimensions="2 2 3")"), std::string::npos);
  // Origin and spacing in XDMF order z y x.
  EXPECT_NE(xmf.find(">0.29999999999999999 0.20000000000000001 0.10000000000000001<"), std::string::npos);
  EXPECT_NE(xmf.find(R"(GeometryType="XYZ")"), std::string::npos);
}

// A rank's part of the grid (NodeGrid::set_part) lands in its box of the whole grid's dataset:
// node (i, j, k) of the part at (begin + (i, j, k)), scalars and vectors alike.
TEST(Frames, GridPartLandsInItsBox) {
  TempDir dir;
  const std::size_t nx = 4, ny = 3, nz = 2;
  const std::array<std::size_t, 3> begin{1, 1, 0}, extent{2, 2, 2};
  const std::size_t n = extent[0] * extent[1] * extent[2];
  std::vector<double> id(n), vx(n), vy(n), vz(n);
  for (std::size_t k = 0; k < extent[2]; ++k)
    for (std::size_t j = 0; j < extent[1]; ++j)
      for (std::size_t i = 0; i < extent[0]; ++i) {
        const std::size_t a = i + extent[0] * (j + extent[1] * k);
        const std::size_t gi = begin[0] + i, gj = begin[1] + j, gk = begin[2] + k;
        id[a] = static_cast<double>(100 * gk + 10 * gj + gi);
        vx[a] = static_cast<double>(gi);
        vy[a] = static_cast<double>(gj);
        vz[a] = static_cast<double>(gk);
      }
  NodeGrid grid(3, {0, 0, 0}, {0.1, 0.1, 0.1}, {nx, ny, nz});
  grid.set_part(begin, extent);
  EXPECT_EQ(grid.count(), n);
  grid.scalar("id", id, "1").vector("velocity", {vx, vy, vz}, "m/s");
  FrameWriter writer(dir.str(), "run");
  const std::string path = writer.write({0.0, 0, {}, grid});
  const auto r = read_h5_doubles(path, "/grid/id");
  const auto v = read_h5_doubles(path, "/grid/velocity");
  ASSERT_EQ(r.shape, (std::vector<std::uint64_t>{nz, ny, nx}));
  ASSERT_EQ(v.shape, (std::vector<std::uint64_t>{nz, ny, nx, 3}));
  int inside = 0;
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t a = (k * ny + j) * nx + i;
        const bool in = i >= begin[0] && i < begin[0] + extent[0] && j >= begin[1] && j < begin[1] + extent[1];
        inside += in ? 1 : 0;
        // (outside the box: HDF5's fill value 0)
        EXPECT_EQ(r.values[a], in ? static_cast<double>(100 * k + 10 * j + i) : 0.0) << i << " " << j << " " << k;
        EXPECT_EQ(v.values[3 * a], in ? static_cast<double>(i) : 0.0);
        EXPECT_EQ(v.values[3 * a + 1], in ? static_cast<double>(j) : 0.0);
        EXPECT_EQ(v.values[3 * a + 2], in ? static_cast<double>(k) : 0.0);
      }
  EXPECT_EQ(inside, static_cast<int>(n));
  NodeGrid other(3, {0, 0, 0}, {0.1, 0.1, 0.1}, {nx, ny, nz});
  EXPECT_THROW(other.set_part({3, 0, 0}, {2, 1, 1}), std::invalid_argument);  // leaves the grid along x
  const std::vector<double> ids(nx * ny * nz, 1.0);
  other.scalar("id", ids, "1");
  EXPECT_THROW(other.set_part(begin, extent), std::invalid_argument);  // after a field
}

TEST(Frames, IndexReferencesExistingDatasetsWithMatchingDimensions) {
  TempDir dir;
  const auto pos = ramp(8, 0.0);
  const auto sc = ramp(4, 1.0);
  const auto t6 = ramp(24, 1.0);
  FrameWriter writer(dir.str());
  for (int k = 0; k < 3; ++k) {
    PointCloud b("grains", 2, pos);
    b.scalar("phi", sc, "1").sym_tensor("stress", t6, "Pa");
    NodeGrid g(2, {0, 0, 0}, {1, 1, 1}, {2, 2, 1});
    g.scalar("mass", sc, "kg");
    writer.write({0.1 * k, 10 * k, {b}, g});
  }
  const std::string xmf_path = writer.index_path();
  const std::string xmf = read_text(xmf_path);
  EXPECT_EQ(xmf.rfind("<?xml", 0), 0u);
  // One temporal collection per block (body "grains", "grid"), one Uniform grid per frame.
  EXPECT_EQ(count_of(xmf, R"(CollectionType="Temporal")"), 2u);
  EXPECT_NE(xmf.find(R"(<Grid Name="grains" GridType="Collection" CollectionType="Temporal">)"), std::string::npos);
  EXPECT_NE(xmf.find(R"(<Grid Name="grid" GridType="Collection" CollectionType="Temporal">)"), std::string::npos);
  EXPECT_EQ(count_of(xmf, R"(GridType="Uniform")"), 2u * 3u);
  EXPECT_EQ(count_of(xmf, "<Time Value="), 2u * 3u);
  EXPECT_EQ(count_of(xmf, R"(<Time Value="0.20000000000000001"/>)"), 2u);
  EXPECT_EQ(count_of(xmf, R"(TopologyType="Polyvertex" NumberOfElements="4")"), 3u);
  EXPECT_EQ(count_of(xmf, R"(AttributeType="Tensor6" Center="Node")"), 3u);
  EXPECT_EQ(count_of(xmf, R"(AttributeType="Scalar" Center="Node")"), 6u);
  EXPECT_EQ(count_of(xmf, "<Grid "), 2u + 2u * 3u);
  EXPECT_EQ(count_of(xmf, "</Grid>"), 2u + 2u * 3u);

  const auto refs = hdf_refs(xmf_path);
  ASSERT_EQ(refs.size(), 3u * 5u);  // connectivity, position, phi, stress, grid mass
  for (const auto& [dims, ref] : refs) {
    const auto colon = ref.find(':');
    ASSERT_NE(colon, std::string::npos) << ref;
    const std::string file = dir.file(ref.substr(0, colon));
    ASSERT_TRUE(fs::exists(file)) << ref;
    const auto data = read_h5_doubles(file, ref.substr(colon + 1));  // converts ints too
    ASSERT_TRUE(data.ok) << ref;
    EXPECT_EQ(data.shape, dims) << ref;
    if (ref.find("/connectivity") != std::string::npos) {
      for (std::size_t i = 0; i < data.values.size(); ++i) EXPECT_EQ(data.values[i], static_cast<double>(i));
    }
  }
}

TEST(Frames, IndexPassesCheckerAfterEveryFrame) {
  TempDir dir;
  if (run_checker(dir.file("none.xmf")) == -1) GTEST_SKIP() << "/usr/bin/python3 not available";
  const auto pos = ramp(9, 0.0);
  const auto v = ramp(9, 1.0);
  FrameWriter writer(dir.str());
  for (int k = 0; k < 3; ++k) {
    PointCloud b("grains", 3, pos);
    b.vector("velocity", 3, v, "m/s");
    NodeGrid g(3, {0, 0, 0}, {1, 1, 1}, {2, 2, 2});
    const auto m = ramp(8, 0.0);
    g.scalar("mass", m, "kg");
    writer.write({0.5 * k, k, {b}, g});
    EXPECT_EQ(run_checker(writer.index_path()), 0) << "after frame " << k;
    EXPECT_EQ(run_checker(writer.index_path(), true), 0) << "after frame " << k;
  }
  // The checker notices dimensions that disagree with the grid...
  const std::string good = read_text(writer.index_path());
  std::string bad = good;
  bad.replace(bad.find(R"(NumberOfElements="3")"), 21, R"(NumberOfElements="4")");
  std::ofstream(dir.file("bad.xmf")) << bad;
  EXPECT_EQ(run_checker(dir.file("bad.xmf"), true), 1);
  // ... a frame file that went missing, or one that is not HDF5.
  fs::remove(writer.frame_path(1));
  EXPECT_EQ(run_checker(writer.index_path()), 1);
  EXPECT_EQ(run_checker(writer.index_path(), true), 1);
  std::ofstream(writer.frame_path(1)) << "not hdf5";
  EXPECT_EQ(run_checker(writer.index_path(), true), 1);
}

TEST(Frames, CheckerRejectsBrokenXml) {
  TempDir dir;
  if (run_checker(dir.file("none.xmf")) == -1) GTEST_SKIP() << "/usr/bin/python3 not available";
  std::ofstream(dir.file("bad.xmf")) << "<Xdmf><Domain><Grid CollectionType=\"Temporal\"></Domain></Xdmf>";
  EXPECT_EQ(run_checker(dir.file("bad.xmf")), 1);
}

TEST(Frames, ResumeKeepsFramesUpToRestartStep) {
  TempDir dir;
  const auto pos = ramp(4, 0.0);
  {
    FrameWriter w(dir.str());
    for (int k = 0; k < 4; ++k) w.write({0.1 * k, 10 * k, {PointCloud("grains", 2, pos)}, std::nullopt});
  }
  // Killed after step 25: frames at steps 30 are from the abandoned future.
  FrameWriter w = FrameWriter::resume(dir.str(), 25);
  EXPECT_EQ(w.frames_written(), 3u);
  EXPECT_FALSE(fs::exists(w.frame_path(3)));
  EXPECT_EQ(count_of(read_text(w.index_path()), "<Time Value="), 3u);  // one block, 3 frames
  const std::string p = w.write({0.27, 27, {PointCloud("grains", 2, pos)}, std::nullopt});
  EXPECT_EQ(p, w.frame_path(3));
  double step = 0;
  ASSERT_TRUE(read_h5_attr(p, "/", "step", step));
  EXPECT_EQ(step, 27.0);
  const std::string xmf = read_text(w.index_path());
  EXPECT_EQ(count_of(xmf, "<Time Value="), 4u);
  EXPECT_NE(xmf.find(R"(<Time Value="0.27000000000000002"/>)"), std::string::npos);
}

TEST(Frames, FreshWriterClearsAnEarlierRun) {
  TempDir dir;
  const auto pos = ramp(4, 0.0);
  {
    FrameWriter w(dir.str());
    for (int k = 0; k < 3; ++k) w.write({0.1 * k, k, {PointCloud("grains", 2, pos)}, std::nullopt});
  }
  std::ofstream(dir.file("frames/frame_000009.h5.tmp-1234")) << "partial";
  std::ofstream(dir.file("frames/notes.txt")) << "kept";
  FrameWriter w(dir.str());
  EXPECT_FALSE(fs::exists(dir.file("frames.xmf")));
  EXPECT_FALSE(fs::exists(dir.file("frames/frame_000001.h5")));
  EXPECT_FALSE(fs::exists(dir.file("frames/frame_000009.h5.tmp-1234")));
  EXPECT_TRUE(fs::exists(dir.file("frames/notes.txt")));
}

TEST(Frames, EmptyBodyStaysOutOfTheIndex) {
  TempDir dir;
  const std::vector<double> none;
  const auto pos = ramp(4, 0.0);
  FrameWriter w(dir.str());
  PointCloud empty("solid", 2, none);
  empty.scalar("mass", none, "kg");
  const std::string p = w.write({0.0, 0, {PointCloud("grains", 2, pos), empty}, std::nullopt});
  const std::string xmf = read_text(w.index_path());
  EXPECT_EQ(xmf.find("Name=\"solid\""), std::string::npos);
  EXPECT_THROW(w.write({0.0, 1, {PointCloud("grid", 2, pos)}, std::nullopt}), std::invalid_argument);
  EXPECT_NE(xmf.find("Name=\"grains\""), std::string::npos);
  auto r = read_h5_doubles(p, "/bodies/solid/mass");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.shape, (std::vector<std::uint64_t>{0}));
}

TEST(Frames, BadInputIsRefused) {
  TempDir dir;
  EXPECT_THROW(FrameWriter(dir.file("missing")), InputError);
  try {
    FrameWriter w(dir.file("missing"));
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos);
  }
  const auto pos = ramp(6, 0.0);
  const auto three = ramp(3, 0.0);
  const auto two = ramp(2, 0.0);
  PointCloud b("grains", 2, pos);  // 3 points
  EXPECT_THROW(b.scalar("p", two, "Pa"), std::invalid_argument);
  EXPECT_THROW(b.vector("v", 4, pos, "m/s"), std::invalid_argument);
  EXPECT_THROW(b.vector("v", {three}, "m/s"), std::invalid_argument);
  EXPECT_THROW(b.scalar("bad name", three, "1"), std::invalid_argument);
  EXPECT_THROW(b.scalar("a<b", three, "1"), std::invalid_argument);
  EXPECT_THROW(b.scalar("position", three, "m"), std::invalid_argument);
  EXPECT_THROW(b.scalar("q", three, ""), std::invalid_argument);     // units required
  EXPECT_THROW(b.scalar("q", three, "m\n"), std::invalid_argument);  // printable only
  EXPECT_THROW(b.scalar("q", three, std::string(65, 'm')), std::invalid_argument);
  EXPECT_THROW(PointCloud("grains", 2, pos, ""), std::invalid_argument);
  b.scalar("p", three, "Pa");
  EXPECT_THROW(b.scalar("p", three, "Pa"), std::invalid_argument);
  EXPECT_THROW(PointCloud("grains", 2, three), std::invalid_argument);  // 3 values, dim 2
  EXPECT_THROW(PointCloud("grains", {three, two}), std::invalid_argument);
  EXPECT_THROW(NodeGrid(2, {0, 0, 0}, {1, 1, 1}, {2, 2, 2}), std::invalid_argument);
  EXPECT_THROW(NodeGrid(3, {0, 0, 0}, {1, 0, 1}, {2, 2, 2}), std::invalid_argument);
  FrameWriter w(dir.str());
  EXPECT_THROW(w.write({0, 0, {b, b}, std::nullopt}), std::invalid_argument);
  EXPECT_EQ(w.frames_written(), 0u);
}

// ParaView itself (when installed: pvbatch) opens the index with its XDMF and Xdmf3 readers and
// finds every block, point, cell and field.
TEST(Frames, ParaViewOpensTheIndex) {
  if (!fs::exists("/usr/bin/pvbatch")) GTEST_SKIP() << "ParaView (pvbatch) not installed";
  TempDir dir;
  const std::vector<double> pos{0, 0, 1, 0, 0, 1}, p{1, 2, 3}, v{1, 0, 0, 1, 1, 1}, m(6, 1.0);
  FrameWriter w(dir.str());
  for (int k = 0; k < 2; ++k) {
    PointCloud b("grains", 2, pos);
    b.scalar("pressure", p, "Pa").vector("velocity", 2, v, "m/s");
    NodeGrid g(2, {0, 0, 0}, {0.5, 0.5, 0}, {3, 2, 1});
    g.scalar("mass", m, "kg");
    w.write({0.1 * k, k, {b}, g});
  }
  const std::string out = dir.file("probe.txt");
  const std::string cmd = "/usr/bin/pvbatch " + std::string(OOBLECK_SOURCE_DIR) + "/tools/paraview_probe.py '" +
                          w.index_path() + "' > '" + out + "' 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string probe = read_text(out);
  // Both readers, both times, both blocks; points as cells; 2D grid in the x-y plane.
  EXPECT_EQ(count_of(probe, R"("class": "vtkUnstructuredGrid", "points": 3, "cells": 3)"), 4u) << probe;
  EXPECT_EQ(count_of(probe, R"("points": 6, "cells": 2, "bounds": [0.0, 1.0, 0.0, 0.5, 0.0, 0.0])"), 4u) << probe;
  EXPECT_EQ(count_of(probe, R"("reader": "xdmf2", "time": 0.1, "block": "grains")"), 1u) << probe;
  EXPECT_EQ(count_of(probe, R"("arrays": {"pressure": 1, "velocity": 3})"), 4u) << probe;
  EXPECT_EQ(count_of(probe, R"("velocity": [1.0, 0.0, 0.0])"), 4u) << probe;
}

// A long index is rewritten less often than every frame but stays valid, and flush() (or the
// destructor) completes it.
TEST(Frames, LongIndexStaysValidAndIsCompletedByFlush) {
  TempDir dir;
  const std::vector<double> pos{0, 0, 1, 1}, val{1, 2};
  const int frames = 150;  // 40 fields x 150 frames: an index of well over 1 MiB
  {
    FrameWriter w(dir.str());
    for (int k = 0; k < frames; ++k) {
      PointCloud b("grains", 2, pos);
      for (int f = 0; f < 40; ++f) b.scalar("field_" + std::to_string(f), val, "1");
      w.write({1e-3 * k, k, {b}, std::nullopt});
      if (k % 25 == 24) {
        const std::string xmf = read_text(w.index_path());
        EXPECT_EQ(count_of(xmf, "<Grid "), count_of(xmf, "</Grid>"));
        EXPECT_NE(xmf.find("</Xdmf>"), std::string::npos);
      }
    }
    EXPECT_GT(fs::file_size(w.index_path()), FrameWriter::kIndexAlwaysBytes);
    w.flush();
    EXPECT_EQ(count_of(read_text(w.index_path()), "<Time Value="), static_cast<std::size_t>(frames));
    w.write({1.0, 1000, {PointCloud("grains", 2, pos)}, std::nullopt});
  }  // the destructor completes the index
  EXPECT_EQ(count_of(read_text(dir.file("frames.xmf")), "<Time Value="), static_cast<std::size_t>(frames + 1));
}
