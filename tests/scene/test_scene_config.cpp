// Scene files: typed, validated configuration; --set overrides with short aliases; errors name
// the file, the key and the rule.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/scene/config.hpp"

using namespace oobleck;

namespace {
const std::string kSettling = std::string(OOBLECK_SOURCE_DIR) + "/scenes/verification/settling.toml";

std::string read_all(const std::string& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// Error message of loading a copy of settling.toml with `from` replaced by `to`.
std::string error_with(const std::string& from, const std::string& to, const std::vector<std::string>& sets = {}) {
  std::string s = read_all(kSettling);
  if (!from.empty()) {
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    s.replace(pos, from.size(), to);
  }
  const auto path = (std::filesystem::temp_directory_path() / "oobleck_scene_test.toml").string();
  std::ofstream(path) << s;
  try {
    scene::load_scene(path, sets);
  } catch (const InputError& e) {
    std::remove(path.c_str());
    return e.what();
  }
  std::remove(path.c_str());
  return "";
}
}  // namespace

TEST(SceneConfig, SettlingSceneLoads) {
  const auto c = scene::load_scene(kSettling);
  EXPECT_EQ(c.name, "settling");
  EXPECT_EQ(c.grid.cells[0], 4);
  EXPECT_EQ(c.grid.cells[1], 20);
  EXPECT_EQ(c.material.name, "hermes2016");
  EXPECT_DOUBLE_EQ(c.material.granular.d, 1e-4);     // override
  EXPECT_DOUBLE_EQ(c.material.steady.phi_j, 0.535);  // from the preset
  EXPECT_DOUBLE_EQ(c.material.steady.eta_0, 1e-3);   // fluid viscosity is the one viscosity
  EXPECT_EQ(c.boundary[0].type, scene::BoundaryType::Periodic);
  ASSERT_EQ(c.regions.size(), 1u);
  EXPECT_DOUBLE_EQ(c.regions[0].phi, 0.1);
  EXPECT_DOUBLE_EQ(c.gravity_m_s2[1], -9.81);
}

TEST(SceneConfig, SetOverridesByAliasAndFullPath) {
  const auto c = scene::load_scene(kSettling, {"phi=0.2", "fluid.kappa=3e5", "grid.shape_function=cubic"});
  EXPECT_DOUBLE_EQ(c.regions[0].phi, 0.2);
  EXPECT_DOUBLE_EQ(c.fluid.kappa_Pa, 3e5);
  EXPECT_EQ(c.grid.shape, scene::ShapeKind::Cubic);
  // A section the file leaves out is created by --set (settling.toml has no [transfer]) ...
  const auto f = scene::load_scene(kSettling, {"transfer.scheme=flip", "transfer.flip_fraction=1.0"});
  EXPECT_EQ(f.transfer.scheme, scene::TransferScheme::Flip);
  EXPECT_DOUBLE_EQ(f.transfer.flip_fraction, 1.0);
  // ... and a misspelt key inside it is still an error with a suggestion.
  try {
    scene::load_scene(kSettling, {"transfer.schme=flip"});
    ADD_FAILURE() << "misspelt key accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'transfer.scheme'"), std::string::npos) << e.what();
  }
}

TEST(SceneConfig, ErrorsNameFileKeyAndRule) {
  std::string e = error_with("kappa = 2.0e5", "kapa = 2.0e5");
  EXPECT_NE(e.find("fluid.kapa"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'fluid.kappa'"), std::string::npos) << e;
  EXPECT_NE(e.find("oobleck_scene_test.toml"), std::string::npos) << e;

  e = error_with("G = 1.0e4", "G = -1.0e4");
  EXPECT_NE(e.find("granular.G"), std::string::npos) << e;
  EXPECT_NE(e.find("positive"), std::string::npos) << e;

  e = error_with("cell_size = 0.001", "cell_size = \"fine\"");
  EXPECT_NE(e.find("grid.cell_size"), std::string::npos) << e;
  EXPECT_NE(e.find("must be a number"), std::string::npos) << e;

  e = error_with("cell_size = 0.001", "cell_size = 0.0015");
  EXPECT_NE(e.find("whole number of cells"), std::string::npos) << e;

  e = error_with("shape_function = \"quadratic\"", "shape_function = \"quadratc\"");
  EXPECT_NE(e.find("did you mean \"quadratic\""), std::string::npos) << e;

  e = error_with("x_max = { type = \"periodic\" }", "x_max = { type = \"slip\" }");
  EXPECT_NE(e.find("periodic faces come in pairs"), std::string::npos) << e;

  e = error_with("", "", {"nosuch.key=1"});
  EXPECT_NE(e.find("no section 'nosuch'"), std::string::npos) << e;
  EXPECT_NE(e.find("short names"), std::string::npos) << e;

  e = error_with("", "", {"phi=1.5"});
  EXPECT_NE(e.find("region[0].phi"), std::string::npos) << e;
  // A bed at or above the material's jamming fraction (hermes2016: phi_j = 0.535) is refused with
  // the region, phi_j and the preset; just below it loads.
  for (const char* phi : {"phi=0.535", "phi=0.6"}) {
    e = error_with("", "", {phi});
    EXPECT_NE(e.find("key 'region[0].phi'"), std::string::npos) << e;
    EXPECT_NE(e.find("region 'region0'"), std::string::npos) << e;  // settling.toml's region has no name
    EXPECT_NE(e.find("phi_j = 0.535 (preset hermes2016)"), std::string::npos) << e;
  }
  EXPECT_EQ(error_with("", "", {"phi=0.534"}), "");
  e = error_with("", "", {"phi=0.5", "material.steady.phi_j=0.45", "material.steady.phi_c=0.40"});
  EXPECT_NE(e.find("phi_j = 0.45"), std::string::npos) << e;
  // The linear kernels' mass floor: a fraction in [0, 1], and only with linear shape functions.
  e = error_with("", "", {"grid.linear_mass_floor=0.1"});
  EXPECT_NE(e.find("grid.linear_mass_floor"), std::string::npos) << e;
  EXPECT_NE(e.find("linear"), std::string::npos) << e;
  e = error_with("", "", {"grid.shape_function=linear", "grid.linear_mass_floor=1.5"});
  EXPECT_NE(e.find("must be in [0, 1]"), std::string::npos) << e;
}

TEST(SceneConfig, BenchmarkScenesLoadWithTheAuthorsPointCounts) {
  const auto a = scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/bench/scenes/intruder_authors_setup.toml");
  EXPECT_EQ(a.grid.geometry, scene::Geometry::Axisymmetric);
  EXPECT_EQ(a.grid.cells[0], 50);
  EXPECT_EQ(a.grid.cells[1], 35);
  const auto b = scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/bench/scenes/wheel_authors_setup.toml");
  EXPECT_EQ(b.grid.cells[0], 150);
  EXPECT_EQ(b.grid.cells[1], 75);
  EXPECT_NEAR(b.grid.cell_size_m, 2.0 / 150.0, 1e-15);
}

namespace {
const std::string kIntrusion = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/intrusion.toml";
/// Error message of loading a copy of intrusion.toml with each `from` replaced by its `to`.
std::string intrusion_error(const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string s = read_all(kIntrusion);
  for (const auto& [from, to] : edits) {
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    s.replace(pos, from.size(), to);
  }
  const auto path = (std::filesystem::temp_directory_path() / "oobleck_body_test.toml").string();
  std::ofstream(path) << s;
  std::string msg;
  try {
    scene::load_scene(path);
  } catch (const InputError& e) {
    msg = e.what();
  }
  std::remove(path.c_str());
  return msg;
}
std::string intrusion_error(const std::string& from, const std::string& to) { return intrusion_error({{from, to}}); }
}  // namespace

TEST(SceneConfig, PaperScenesLoadWithTheirBodiesAndAliases) {
  const auto i = scene::load_scene(kIntrusion, {"v0=0.5", "phi=0.49"});
  ASSERT_EQ(i.bodies.size(), 1u);
  EXPECT_EQ(i.bodies[0].motion, scene::BodyMotionKind::Prescribed);
  EXPECT_DOUBLE_EQ(i.bodies[0].velocity_m_s[1], -0.5);
  EXPECT_DOUBLE_EQ(i.regions[0].phi, 0.49);
  EXPECT_EQ(i.analysis.kind, scene::AnalysisKind::Intrusion);
  EXPECT_EQ(i.analysis.body, "intruder");
  const auto w = scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/wheel.toml", {"omega=1"});
  ASSERT_EQ(w.bodies.size(), 1u);
  EXPECT_EQ(w.bodies[0].shape, scene::BodyShape::Wheel);
  EXPECT_DOUBLE_EQ(*w.bodies[0].motor_omega_rad_s, 1.0);
  const auto r = scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/rod_impact.toml", {"eta_0=1e-3"});
  EXPECT_DOUBLE_EQ(*r.bodies[0].mass_kg, 0.3);
  EXPECT_DOUBLE_EQ(r.fluid.eta_0_Pa_s, 1e-3);
}

/// Every committed scene file loads and validates, is named after its file (the default run
/// folder is out/<name>), and every paper scene takes the short overrides issue 5 asks of all of
/// them: --set phi=... and --set eta_0=....
TEST(SceneConfig, EveryCommittedSceneFileLoads) {
  namespace fs = std::filesystem;
  int paper = 0, others = 0;
  for (const char* dir : {"scenes/paper", "scenes/verification", "bench/scenes"}) {
    for (const auto& e : fs::directory_iterator(fs::path(OOBLECK_SOURCE_DIR) / dir)) {
      if (e.path().extension() != ".toml") continue;
      SCOPED_TRACE(e.path().string());
      const bool is_paper = std::string(dir) == "scenes/paper";
      const auto c = is_paper ? scene::load_scene(e.path().string(), {"phi=0.4825", "eta_0=0.0031"})
                              : scene::load_scene(e.path().string());
      EXPECT_EQ(c.name, e.path().stem().string());
      if (is_paper) {
        ASSERT_FALSE(c.regions.empty());
        EXPECT_DOUBLE_EQ(c.regions[0].phi, 0.4825);
        EXPECT_DOUBLE_EQ(c.fluid.eta_0_Pa_s, 0.0031);
        ++paper;
      } else {
        ++others;
      }
    }
  }
  EXPECT_GE(paper, 6);   // annular shear, intrusion (+ deep bed), rod impact (+ large), wheel
  EXPECT_GE(others, 5);  // three verification scenes, two benchmark set-ups
}

TEST(SceneConfig, TiltedCylinderTurnsItsAxisAndLaunchVelocity) {
  const std::string f = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/rod_impact_3d.toml";
  const auto c = scene::load_scene(f, {"tilt_deg=30", "v0=2"});
  const auto& b = c.bodies[0];
  EXPECT_EQ(b.shape, scene::BodyShape::Cylinder);
  // (0, 0, -2) turned by 30 deg about y towards +x on top: down and towards -x, |v| = 2.
  EXPECT_NEAR(b.velocity_m_s[0], -1.0, 1e-12);
  EXPECT_NEAR(b.velocity_m_s[1], 0.0, 1e-12);
  EXPECT_NEAR(b.velocity_m_s[2], -std::sqrt(3.0), 1e-12);
  const auto fr = scene::cylinder_frame(b);
  EXPECT_NEAR(fr.axis[0], 0.5, 1e-12);
  EXPECT_NEAR(fr.axis[2], std::sqrt(3.0) / 2, 1e-12);
  // The bottom rim's lowest point stays on the surface: base raised by r sin 30 = r/2.
  EXPECT_NEAR(fr.base_m[2], 0.1 + 0.5 * b.radius_m, 1e-15);
  EXPECT_NEAR(fr.lo_m[2], 0.1, 1e-15);  // lowest point of the bottom rim: base_z - r sin 30
  // Top face centre at base + L axis; its rim reaches r cos 30 further along x.
  EXPECT_NEAR(fr.hi_m[0], b.length_m * 0.5 + b.radius_m * std::sqrt(3.0) / 2, 1e-15);
}

TEST(SceneConfig, VariantsApplyTheirOverridesWhenSetTrue) {
  const std::string f = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/wheel_3d.toml";
  const auto walled = scene::load_scene(f, {"width_periodic=false"});
  EXPECT_EQ(walled.boundary[2].type, scene::BoundaryType::NoSlip);
  EXPECT_DOUBLE_EQ(walled.bodies[0].width_m, 0.3);
  EXPECT_EQ(walled.grid.cells[1], 45);
  // The variant, then a later --set (cells keep cubic cells of 33.3 mm: 60 x 4 x 30).
  const auto c = scene::load_scene(f, {"width_periodic=true", "cells=[60, 4, 30]", "omega=1"});
  EXPECT_EQ(c.boundary[2].type, scene::BoundaryType::Periodic);
  EXPECT_EQ(c.boundary[3].type, scene::BoundaryType::Periodic);
  EXPECT_DOUBLE_EQ(c.bodies[0].width_m, c.grid.size_m[1]);  // the wheel spans the period
  EXPECT_DOUBLE_EQ(c.regions[0].max_m[1], c.grid.size_m[1]);
  EXPECT_EQ(c.grid.cells[1], 4);
  EXPECT_DOUBLE_EQ(*c.bodies[0].motor_omega_rad_s, 1.0);
  try {
    scene::load_scene(f, {"width_periodic=yes"});
    ADD_FAILURE() << "a variant takes true or false";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("takes true or false"), std::string::npos) << e.what();
  }
  try {
    scene::load_scene(f, {"body.0.width=0.7"});
    ADD_FAILURE() << "a wheel wider than the walled bed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("body[0].width"), std::string::npos) << e.what();
  }
}

TEST(SceneConfig, BodyErrorsNameTheKeyAndRule) {
  EXPECT_NE(intrusion_error("density = 2700.0", "density = -1.0").find("body[0].density"), std::string::npos);
  // Names become folders and HDF5 groups: refused at load time, before any output.
  EXPECT_NE(intrusion_error("name = \"intruder\"", "name = \"my rod\"").find("body[0].name"), std::string::npos);
  EXPECT_NE(intrusion_error("name = \"intrusion\"", "name = \"runs/intrusion\"").find("out/<name>"), std::string::npos);
  EXPECT_NE(intrusion_error("density = 2700.0", "mass = 1.0").find("only a free rigid body takes a mass"),
            std::string::npos);
  EXPECT_NE(intrusion_error("max = [0.005, 0.035]", "max = [0.005, 0.045]").find("inside the grid"), std::string::npos);
  EXPECT_NE(
      intrusion_error("motion = \"prescribed\"", "motion = \"rigid\"").find("must be one of prescribed, free, elastic"),
      std::string::npos);
  EXPECT_NE(intrusion_error("friction = 0.3", "friction = 0.3\nmotor_omega = 3").find("only an elastic body"),
            std::string::npos);
  EXPECT_NE(intrusion_error("ramp_time = 0.0 ", "ramp_time = -0.001 ").find("body[0].ramp_time"), std::string::npos);
  EXPECT_NE(
      intrusion_error({{"motion = \"prescribed\"", "motion = \"free\""}, {"ramp_time = 0.0 ", "ramp_time = 0.002 "}})
          .find("only a prescribed body"),
      std::string::npos);
  EXPECT_NE(
      intrusion_error("kind = \"intrusion\"", "kind = \"intrusion\"\nbody = \"rod\"").find("no [[body]] has that name"),
      std::string::npos);
  EXPECT_NE(intrusion_error("kind = \"intrusion\"", "kind = \"wheel\"").find("plane-strain or 3D grid"),
            std::string::npos);
  EXPECT_NE(intrusion_error("name = \"intruder\"", "name = \"grains\"").find("differ from the phases"),
            std::string::npos);
  EXPECT_NE(intrusion_error("shape = \"box\"", "shape = \"cylinder\"").find("cylinders are 3D bodies"),
            std::string::npos);
  const std::string rod3d = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/rod_impact_3d.toml";
  auto rod3d_error = [&](const std::string& set) {
    try {
      scene::load_scene(rod3d, {set});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(rod3d_error("tilt_deg=90").find("body[0].tilt"), std::string::npos);
  EXPECT_NE(rod3d_error("body.0.radius=0").find("body[0].radius"), std::string::npos);
  EXPECT_NE(rod3d_error("body.0.length=0.05").find("inside the grid"), std::string::npos);  // top above z = 0.14
}
