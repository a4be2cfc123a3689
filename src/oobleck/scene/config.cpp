#include "oobleck/scene/config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/frames.hpp"
#include "oobleck/io/toml_reader.hpp"
#include "oobleck/rheology/parameter_table.hpp"

namespace oobleck::scene {

namespace {

template <class E, std::size_t N>
E parse_enum(io::TomlReader& t, std::string_view key, E fallback,
             const std::array<std::pair<const char*, E>, N>& names) {
  if (!t.has(key)) {
    (void)t.string_or(key, "");
    return fallback;
  }
  const std::string v = t.string(key);
  std::vector<std::string> options;
  for (const auto& [n, e] : names) {
    if (v == n) return e;
    options.emplace_back(n);
  }
  const std::string hint = closest_match(v, options);
  t.fail(key, fmt::format("= \"{}\": must be one of {}{}", v, fmt::join(options, ", "),
                          hint.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", hint)));
}

/// Read an array of `dim` numbers (or fewer allowed = `min_len`) into a 3-array.
std::array<double, 3> read_vec(io::TomlReader& t, std::string_view key, int dim, std::array<double, 3> fallback,
                               bool required, int min_len = -1) {
  if (min_len < 0) min_len = dim;
  if (!t.has(key)) {
    if (required) t.fail(key, fmt::format("missing (required array of {} numbers)", dim));
    (void)t.optional_number(key);  // records the key as known
    return fallback;
  }
  const toml::array* arr = t.raw(key)->as_array();
  if (arr == nullptr) t.fail(key, fmt::format("must be an array of {} numbers [m, ...]", dim));
  if (static_cast<int>(arr->size()) < min_len || static_cast<int>(arr->size()) > 3 ||
      (min_len == dim && static_cast<int>(arr->size()) != dim && dim == 3)) {
    t.fail(key, fmt::format("has {} entries; expected {}", arr->size(), dim));
  }
  std::array<double, 3> out = fallback;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const auto v = (*arr)[i].value<double>();
    if (!v || !std::isfinite(*v)) t.fail(key, fmt::format("entry {} is not a finite number", i));
    out[i] = *v;
  }
  return out;
}

void set_material_overrides(rheology::Preset& p, io::TomlReader& mat) {
  for (const rheology::Section section : {rheology::Section::Steady, rheology::Section::Granular}) {
    auto t = mat.optional_table(rheology::section_name(section));
    if (!t) continue;
    for (const rheology::Parameter& row : rheology::parameter_table()) {
      if (row.section != section) continue;
      double& v = rheology::value(p, row);
      v = t->number_or(row.name, v);
    }
    t->finish();
  }
}

}  // namespace

std::string override_key(const std::string& spec, const std::map<std::string, std::string>& aliases) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError(fmt::format("--set '{}': expected key=value", spec));
  }
  const std::string key = spec.substr(0, eq);
  const auto it = aliases.find(key);
  return it != aliases.end() ? it->second : key;
}

namespace {

/// Apply one --set override to the parsed document.
void apply_override(toml::table& root, const std::string& file, const std::string& spec,
                    const std::map<std::string, std::string>& aliases) {
  const std::string key = override_key(spec, aliases);
  const std::string value = spec.substr(spec.find('=') + 1);
  // Parse the value as a TOML value; bare words become strings.
  toml::table holder;
  try {
    holder = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    holder.insert_or_assign("v", value);
  }
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');) parts.push_back(part);
  toml::node* node = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& part = parts[i];
    if (auto* tbl = node->as_table()) {
      node = tbl->get(part);
      // A section the file leaves out (defaults apply) is created, so that --set reaches every
      // documented key; a name that is not a section stays an error here, a wrong key inside a
      // created section is caught by the key validation that follows (with a suggestion).
      constexpr std::array<const char*, 10> kOptionalSections{"coupling", "transfer", "analysis", "physics", "output",
                                                              "time",     "fluid",    "material", "scene",   "aliases"};
      if (node == nullptr &&
          (i > 0 || std::find(kOptionalSections.begin(), kOptionalSections.end(), part) != kOptionalSections.end())) {
        tbl->insert(part, toml::table{});
        node = tbl->get(part);
      }
    } else if (auto* arr = node->as_array()) {
      char* end = nullptr;
      const long idx = std::strtol(part.c_str(), &end, 10);
      node = (end != part.c_str() && *end == '\0' && idx >= 0 && idx < static_cast<long>(arr->size()))
                 ? arr->get(static_cast<std::size_t>(idx))
                 : nullptr;
    } else {
      node = nullptr;
    }
    if (node == nullptr) {
      std::vector<std::string> alias_names;
      alias_names.reserve(aliases.size());
      for (const auto& [a, target] : aliases) alias_names.push_back(a);
      throw InputError(fmt::format(
          "--set {}: {} has no section '{}'{}", spec, file, part,
          alias_names.empty() ? std::string() : fmt::format(" (short names: {})", fmt::join(alias_names, ", "))));
    }
  }
  if (auto* arr = node->as_array()) {  // an entry of an array: velocity.1, snapshot_times.0
    char* end = nullptr;
    const std::string& last = parts.back();
    const long idx = std::strtol(last.c_str(), &end, 10);
    if (end == last.c_str() || *end != '\0' || idx < 0 || idx >= static_cast<long>(arr->size())) {
      throw InputError(
          fmt::format("--set {}: '{}' has no entry {} in {} (it has {})", spec, key, last, file, arr->size()));
    }
    arr->replace(arr->cbegin() + idx, *holder.get("v"));
    return;
  }
  auto* parent = node->as_table();
  if (parent == nullptr) throw InputError(fmt::format("--set {}: '{}' is not a table in {}", spec, key, file));
  parent->insert_or_assign(parts.back(), *holder.get("v"));
}

constexpr std::array<std::pair<const char*, Geometry>, 3> kGeometries{
    {{"plane_strain", Geometry::PlaneStrain}, {"axisymmetric", Geometry::Axisymmetric}, {"3d", Geometry::ThreeD}}};
constexpr std::array<std::pair<const char*, ShapeKind>, 4> kShapes{{{"linear", ShapeKind::Linear},
                                                                    {"quadratic", ShapeKind::Quadratic},
                                                                    {"cubic", ShapeKind::Cubic},
                                                                    {"ugimp", ShapeKind::UGimp}}};
constexpr std::array<std::pair<const char*, BoundaryType>, 7> kBoundaries{{{"no_slip", BoundaryType::NoSlip},
                                                                           {"axis", BoundaryType::Axis},
                                                                           {"slip", BoundaryType::Slip},
                                                                           {"friction", BoundaryType::Friction},
                                                                           {"velocity", BoundaryType::Velocity},
                                                                           {"periodic", BoundaryType::Periodic},
                                                                           {"open", BoundaryType::Open}}};
constexpr std::array<std::pair<const char*, Phase>, 4> kPhases{
    {{"mixture", Phase::Mixture}, {"fluid", Phase::Fluid}, {"grains", Phase::Grains}, {"elastic", Phase::Elastic}}};

constexpr std::array<std::pair<const char*, BodyShape>, 4> kBodyShapes{{{"box", BodyShape::Box},
                                                                        {"disc", BodyShape::Disc},
                                                                        {"wheel", BodyShape::Wheel},
                                                                        {"cylinder", BodyShape::Cylinder}}};
constexpr std::array<std::pair<const char*, BodyMotionKind>, 3> kMotions{
    {{"prescribed", BodyMotionKind::Prescribed}, {"free", BodyMotionKind::Free}, {"elastic", BodyMotionKind::Elastic}}};
constexpr std::array<std::pair<const char*, AnalysisKind>, 7> kAnalyses{{{"none", AnalysisKind::None},
                                                                         {"settling", AnalysisKind::Settling},
                                                                         {"couette", AnalysisKind::Couette},
                                                                         {"annular", AnalysisKind::Annular},
                                                                         {"intrusion", AnalysisKind::Intrusion},
                                                                         {"rod", AnalysisKind::Rod},
                                                                         {"wheel", AnalysisKind::Wheel}}};

// ---- One reader per section of the scene file, in the order load_scene calls them. Each
// validates its keys as it reads them; the first error throws (file, key and reason), so the
// order of the reads decides which of several errors is reported and is kept as it is.

/// [scene]: the run's name (it names the folder out/<name>) and a description.
void read_scene(io::TomlReader& top, SceneConfig& c) {
  io::TomlReader sc = top.table("scene");
  c.name = sc.string("name");
  if (!io::is_plain_name(c.name))
    sc.fail("name", fmt::format("= \"{}\": {} (it names the run folder out/<name>)", c.name, io::kPlainNameRule));
  c.description = sc.string_or("description", "");
  sc.finish();
}

/// [grid]: geometry, extent, square cells and the shape functions.
GridConfig read_grid(io::TomlReader& top) {
  io::TomlReader g = top.table("grid");
  GridConfig grid;
  grid.geometry = parse_enum(g, "geometry", Geometry::PlaneStrain, kGeometries);
  grid.dim = grid.geometry == Geometry::ThreeD ? 3 : 2;
  const int dim = grid.dim;
  grid.origin_m = read_vec(g, "origin", dim, {0, 0, 0}, false);
  grid.size_m = read_vec(g, "size", dim, {0, 0, 0}, true);
  // Either cell_size [m] (size must be a whole number of cells) or cells along the first axis.
  if (g.has("cells")) {
    const auto n = read_vec(g, "cells", dim, {1, 1, 1}, true);
    if (g.has("cell_size")) g.fail("cells", "give either grid.cells or grid.cell_size, not both");
    (void)g.optional_number("cell_size");
    g.require(n[0] >= 1 && n[0] == std::floor(n[0]), "cells", n[0], "entries must be whole numbers >= 1");
    grid.cell_size_m = grid.size_m[0] / n[0];
  } else {
    grid.cell_size_m = g.number("cell_size");
  }
  g.require(grid.cell_size_m > 0.0 && std::isfinite(grid.cell_size_m), "cell_size", grid.cell_size_m,
            "must be positive [m]");
  for (int a = 0; a < dim; ++a) {
    const double n = grid.size_m[a] / grid.cell_size_m;
    g.require(grid.size_m[a] > 0.0, "size", grid.size_m[a], fmt::format("entry {} must be positive [m]", a));
    g.require(std::fabs(n - std::round(n)) < 1e-6 * n, "size", grid.size_m[a],
              fmt::format("entry {} must be a whole number of cells of size {} m (square cells)", a, grid.cell_size_m));
    grid.cells[a] = static_cast<int>(std::lround(n));
  }
  if (grid.geometry == Geometry::Axisymmetric) {
    g.require(grid.origin_m[0] >= 0.0, "origin", grid.origin_m[0], "axisymmetric: r_0 = origin[0] must be >= 0");
  }
  grid.shape = parse_enum(g, "shape_function", ShapeKind::Quadratic, kShapes);
  if (g.has("linear_mass_floor")) {
    if (grid.shape != ShapeKind::Linear)
      g.fail("linear_mass_floor", "applies to shape_function = \"linear\" only (B-splines have no mass floor)");
    const double floor = g.number("linear_mass_floor");
    g.require(floor >= 0.0 && floor <= 1.0, "linear_mass_floor", floor,
              "must be in [0, 1] (a fraction of a full node's mass; 0: off)");
    grid.linear_mass_floor = floor;
  }
  g.finish();
  return grid;
}

/// [material]: a preset or a params file (relative to the scene file), plus overrides.
rheology::Preset read_material(io::TomlReader& top, const std::string& path) {
  io::TomlReader m = top.table("material");
  const std::string preset = m.string_or("preset", "");
  const std::string params = m.string_or("params", "");
  if (preset.empty() == params.empty()) m.fail("preset", "give exactly one of material.preset or material.params");
  rheology::Preset material;
  if (!preset.empty()) {
    material = rheology::load_preset(preset);
  } else {
    const auto rel = std::filesystem::path(path).parent_path() / params;
    material = rheology::load_params_file(std::filesystem::path(params).is_absolute() ? params : rel.string());
  }
  set_material_overrides(material, m);
  m.finish();
  rheology::validate(material, path + " [material]");
  return material;
}

/// [fluid]; its eta_0 (default: the material's) becomes the material's too: one viscosity for
/// both laws.
void read_fluid(io::TomlReader& top, SceneConfig& c) {
  c.fluid.eta_0_Pa_s = c.material.steady.eta_0;
  if (auto f = top.optional_table("fluid")) {
    for (const rheology::Parameter& row : rheology::parameter_table()) {
      if (row.section != rheology::Section::Fluid) continue;
      double& v = rheology::value(c.fluid, row);
      v = f->number_or(row.name, v);
      f->require(rheology::admissible(row, v), row.name, v, rheology::rule(row));
    }
    f->finish();
  }
  c.material.steady.eta_0 = c.fluid.eta_0_Pa_s;
}

/// [coupling]: the drag law and the porosity clamp.
CouplingConfig read_coupling(io::TomlReader& top) {
  CouplingConfig coupling;
  if (auto cp = top.optional_table("coupling")) {
    constexpr std::array<std::pair<const char*, DragLaw>, 2> kDrag{
        {{"beetstra", DragLaw::Beetstra}, {"carman_kozeny", DragLaw::CarmanKozeny}}};
    coupling.drag = parse_enum(*cp, "drag", DragLaw::Beetstra, kDrag);
    coupling.porosity_min = cp->number_or("porosity_min", coupling.porosity_min);
    cp->require(coupling.porosity_min > 0 && coupling.porosity_min < 1, "porosity_min", coupling.porosity_min,
                "must lie in (0, 1)");
    cp->finish();
  }
  return coupling;
}

/// [transfer]: APIC or FLIP and the FLIP/PIC blend.
TransferConfig read_transfer(io::TomlReader& top) {
  TransferConfig transfer;
  if (auto tr = top.optional_table("transfer")) {
    constexpr std::array<std::pair<const char*, TransferScheme>, 2> kSchemes{
        {{"apic", TransferScheme::Apic}, {"flip", TransferScheme::Flip}}};
    transfer.scheme = parse_enum(*tr, "scheme", TransferScheme::Apic, kSchemes);
    transfer.flip_fraction = tr->number_or("flip_fraction", transfer.flip_fraction);
    tr->require(transfer.flip_fraction >= 0 && transfer.flip_fraction <= 1, "flip_fraction", transfer.flip_fraction,
                "must lie in [0, 1]");
    tr->finish();
  }
  return transfer;
}

/// One [[region]] table: a box of material points inside the grid. A bed of grains must lie below
/// the material's jamming fraction phi_j (E1: the packing at full structure), where the steady
/// model has a flowing state.
RegionConfig read_region(io::TomlReader& r, std::size_t index, const GridConfig& grid,
                         const rheology::Preset& material) {
  const int dim = grid.dim;
  RegionConfig reg;
  reg.name = r.string_or("name", fmt::format("region{}", index));
  reg.phase = parse_enum(r, "phase", Phase::Mixture, kPhases);
  reg.min_m = read_vec(r, "min", dim, {0, 0, 0}, true);
  reg.max_m = read_vec(r, "max", dim, {0, 0, 0}, true);
  for (int a = 0; a < dim; ++a) {
    r.require(reg.max_m[a] > reg.min_m[a], "max", reg.max_m[a], fmt::format("entry {} must exceed min[{}]", a, a));
    r.require(reg.min_m[a] >= grid.origin_m[a] - 1e-12 && reg.max_m[a] <= grid.origin_m[a] + grid.size_m[a] + 1e-12,
              "max", reg.max_m[a], fmt::format("the box must lie inside the grid along axis {}", a));
  }
  const bool has_grains = reg.phase == Phase::Mixture || reg.phase == Phase::Grains;
  reg.phi = has_grains ? r.number("phi") : r.number_or("phi", 0.0);
  if (has_grains) {
    r.require(reg.phi > 0 && reg.phi < 1, "phi", reg.phi, "must lie in (0, 1)");
    r.require(reg.phi < material.steady.phi_j, "phi", reg.phi,
              fmt::format("region '{}': must lie below the material's jamming fraction phi_j = {:g} ({}{}): a bed "
                          "at or above phi_j has no flowing state",
                          reg.name, material.steady.phi_j, material.name.empty() ? "its [material]" : "preset ",
                          material.name));
  }
  reg.points_per_cell = static_cast<int>(r.number_or("points_per_cell", 2));
  r.require(reg.points_per_cell >= 1 && reg.points_per_cell <= 8, "points_per_cell", reg.points_per_cell,
            "must be an integer in [1, 8] (per axis)");
  const int ncomp = grid.geometry == Geometry::PlaneStrain ? 2 : 3;
  reg.velocity_m_s = read_vec(r, "velocity", ncomp, {0, 0, 0}, false, dim);
  constexpr std::array<std::pair<const char*, InitialState>, 3> kInit{{{"at_rest", InitialState::AtRest},
                                                                       {"hydrostatic", InitialState::Hydrostatic},
                                                                       {"suspended", InitialState::Suspended}}};
  reg.initial_state = parse_enum(r, "initial_state", InitialState::AtRest, kInit);
  if (reg.phase == Phase::Elastic) {
    reg.elastic.density_kg_m3 = r.number("density");
    reg.elastic.youngs_modulus_Pa = r.number("youngs_modulus");
    reg.elastic.poisson_ratio = r.number_or("poisson_ratio", 0.3);
    r.require(reg.elastic.density_kg_m3 > 0, "density", reg.elastic.density_kg_m3, "must be positive [kg/m^3]");
    r.require(reg.elastic.youngs_modulus_Pa > 0, "youngs_modulus", reg.elastic.youngs_modulus_Pa,
              "must be positive [Pa]");
    r.require(reg.elastic.poisson_ratio > -1 && reg.elastic.poisson_ratio < 0.5, "poisson_ratio",
              reg.elastic.poisson_ratio, "must lie in (-1, 0.5)");
  }
  r.finish();
  return reg;
}

/// [[region]]: at least one.
std::vector<RegionConfig> read_regions(io::TomlReader& top, const GridConfig& grid, const rheology::Preset& material) {
  auto regions = top.table_array("region");
  if (regions.empty()) top.fail("region", "missing: at least one [[region]] of material points is required");
  std::vector<RegionConfig> out;
  for (std::size_t i = 0; i < regions.size(); ++i) out.push_back(read_region(regions[i], i, grid, material));
  return out;
}

/// One face's table of [boundary] (x_min, ...). `axis_face`: the face r = 0 of an axisymmetric
/// grid, which must be (and is the only one that may be) of type "axis".
void read_face(io::TomlReader& fb, const GridConfig& grid, bool axis_face, BoundaryConfig& bc) {
  bc.type = parse_enum(fb, "type", BoundaryType::NoSlip, kBoundaries);
  if (bc.type == BoundaryType::Friction) {
    bc.friction = fb.number("friction");
    fb.require(bc.friction >= 0, "friction", bc.friction, "must be >= 0");
  }
  if (bc.type == BoundaryType::Velocity) {
    const int ncomp = grid.geometry == Geometry::PlaneStrain ? 2 : 3;
    bc.velocity_m_s = read_vec(fb, "velocity", ncomp, {0, 0, 0}, true, grid.dim);
  }
  if (axis_face != (bc.type == BoundaryType::Axis)) {
    fb.fail("type", axis_face ? "the face r = 0 of an axisymmetric grid is the axis: type must be \"axis\""
                              : "type \"axis\" is only valid for x_min of an axisymmetric grid with origin r = 0");
  }
  fb.finish();
}

/// [boundary]: one table per face (default no-slip); on the axis of an axisymmetric grid
/// (r_0 = 0) only v_r and v_theta vanish. Periodic faces come in pairs, never on the axis.
std::array<BoundaryConfig, 6> read_boundary(io::TomlReader& top, const std::string& path, const GridConfig& grid) {
  std::array<BoundaryConfig, 6> boundary;
  const int dim = grid.dim;
  const bool on_axis = grid.geometry == Geometry::Axisymmetric && grid.origin_m[0] == 0.0;
  if (on_axis) boundary[0].type = BoundaryType::Axis;
  if (auto b = top.optional_table("boundary")) {
    for (int face = 0; face < 2 * dim; ++face) {
      if (auto fb = b->optional_table(face_names()[face])) read_face(*fb, grid, on_axis && face == 0, boundary[face]);
    }
    b->finish();
  }
  for (int a = 0; a < dim; ++a) {
    const bool lo = boundary[2 * a].type == BoundaryType::Periodic;
    const bool hi = boundary[2 * a + 1].type == BoundaryType::Periodic;
    if (lo != hi) {
      throw InputError(fmt::format("{}: key 'boundary.{}': periodic faces come in pairs ({} and {})", path,
                                   face_names()[2 * a], face_names()[2 * a], face_names()[2 * a + 1]));
    }
  }
  if (grid.geometry == Geometry::Axisymmetric && boundary[0].type == BoundaryType::Periodic) {
    throw InputError(fmt::format("{}: key 'boundary.x_min': the radial axis cannot be periodic", path));
  }
  return boundary;
}

/// A [[body]]'s shape: a box, (plane strain) a disc or a paddle wheel, or (3D) a cylinder, inside
/// the grid along every axis that is not periodic.
void read_body_shape(io::TomlReader& r, const SceneConfig& c, BodyConfig& b) {
  const int dim = c.grid.dim;
  auto inside_grid = [&](std::string_view key, double lo, double hi, int a) {
    r.require(lo >= c.grid.origin_m[a] - 1e-12 && hi <= c.grid.origin_m[a] + c.grid.size_m[a] + 1e-12, key, hi,
              fmt::format("the body must lie inside the grid along axis {}", a));
  };
  if (b.shape == BodyShape::Cylinder) {
    if (c.grid.geometry != Geometry::ThreeD) {
      r.fail("shape", "cylinders are 3D bodies (axisymmetric: a box from r = 0 is a cylinder on the axis)");
    }
    b.centre_m = read_vec(r, "centre", dim, {0, 0, 0}, true);
    b.radius_m = r.number("radius");
    b.length_m = r.number("length");
    b.tilt_deg = r.number_or("tilt", 0.0);
    r.require(b.radius_m > 0, "radius", b.radius_m, "must be positive [m]");
    r.require(b.length_m > 0, "length", b.length_m, "must be positive [m]");
    r.require(std::fabs(b.tilt_deg) < 90.0, "tilt", b.tilt_deg, "must lie in (-90, 90) [deg] from the vertical");
    const CylinderFrame f = cylinder_frame(b);
    for (int a = 0; a < dim; ++a) {
      if (!(c.boundary[2 * a].type == BoundaryType::Periodic)) inside_grid("centre", f.lo_m[a], f.hi_m[a], a);
    }
    return;
  }
  if (b.shape == BodyShape::Box) {
    b.min_m = read_vec(r, "min", dim, {0, 0, 0}, true);
    b.max_m = read_vec(r, "max", dim, {0, 0, 0}, true);
    for (int a = 0; a < dim; ++a) {
      r.require(b.max_m[a] > b.min_m[a], "max", b.max_m[a], fmt::format("entry {} must exceed min[{}]", a, a));
      if (!(c.boundary[2 * a].type == BoundaryType::Periodic)) inside_grid("max", b.min_m[a], b.max_m[a], a);
    }
    return;
  }
  if (c.grid.geometry == Geometry::Axisymmetric) {
    r.fail("shape", "discs and wheels are plane-strain or 3D bodies (axisymmetric: a box from r = 0 is a cylinder)");
  }
  b.centre_m = read_vec(r, "centre", dim, {0, 0, 0}, true);
  if (dim == 3) {  // in the (x, z) plane, the axle along y
    b.width_m = r.number("width");
    r.require(b.width_m > 0, "width", b.width_m, "must be positive [m] (the extent along y)");
    if (!(c.boundary[2].type == BoundaryType::Periodic))
      inside_grid("width", b.centre_m[1] - 0.5 * b.width_m, b.centre_m[1] + 0.5 * b.width_m, 1);
  }
  double R = 0.0;
  if (b.shape == BodyShape::Disc) {
    b.radius_m = r.number("radius");
    r.require(b.radius_m > 0, "radius", b.radius_m, "must be positive [m]");
    R = b.radius_m;
  } else {
    b.hub_radius_m = r.number("hub_radius");
    b.paddle_length_m = r.number("paddle_length");
    b.paddle_width_m = r.number("paddle_width");
    const double np = r.number_or("paddles", 4);
    b.angle_deg = r.number_or("angle", 0.0);
    r.require(b.hub_radius_m > 0, "hub_radius", b.hub_radius_m, "must be positive [m]");
    r.require(b.paddle_length_m >= 0, "paddle_length", b.paddle_length_m, "must be >= 0 [m]");
    r.require(b.paddle_width_m > 0 && b.paddle_width_m <= 2 * b.hub_radius_m, "paddle_width", b.paddle_width_m,
              "must lie in (0, 2 hub_radius] [m]");
    r.require(np >= 1 && np <= 32 && np == std::floor(np), "paddles", np, "must be a whole number in [1, 32]");
    b.paddles = static_cast<int>(np);
    R = b.hub_radius_m + b.paddle_length_m;
  }
  for (int a = 0; a < dim; a += dim - 1) {  // the plane of the disc or wheel: x and the last axis
    if (!(c.boundary[2 * a].type == BoundaryType::Periodic))
      inside_grid("centre", b.centre_m[a] - R, b.centre_m[a] + R, a);
  }
}

/// A [[body]]'s mass (free rigid bodies: mass or density) and, for an elastic body, its moduli and
/// motor; the elastic keys are refused on the other bodies.
void read_body_material(io::TomlReader& r, const SceneConfig& c, BodyConfig& b) {
  b.mass_kg = r.optional_number("mass");
  if (b.mass_kg) {
    r.require(*b.mass_kg > 0, "mass", *b.mass_kg, "must be positive [kg]");
    if (b.motion != BodyMotionKind::Free) r.fail("mass", "only a free rigid body takes a mass (it sets its density)");
    if (r.has("density")) r.fail("mass", "give either density or mass, not both");
    (void)r.optional_number("density");
  } else {
    b.density_kg_m3 = r.number("density");
    r.require(b.density_kg_m3 > 0, "density", b.density_kg_m3, "must be positive [kg/m^3]");
  }
  if (b.motion == BodyMotionKind::Elastic) {
    b.youngs_modulus_Pa = r.number("youngs_modulus");
    b.poisson_ratio = r.number_or("poisson_ratio", 0.3);
    r.require(b.youngs_modulus_Pa > 0, "youngs_modulus", b.youngs_modulus_Pa, "must be positive [Pa]");
    r.require(b.poisson_ratio > -1 && b.poisson_ratio < 0.5, "poisson_ratio", b.poisson_ratio, "must lie in (-1, 0.5)");
    b.motor_omega_rad_s = r.optional_number("motor_omega");
    b.motor_gain = r.number_or("motor_gain", 1.0);
    r.require(b.motor_gain > 0 && b.motor_gain <= 1, "motor_gain", b.motor_gain, "must lie in (0, 1]");
    if (b.motor_omega_rad_s && c.grid.geometry == Geometry::Axisymmetric) {
      r.fail("motor_omega", "motors are implemented in plane strain and 3D only");
    }
  } else {
    for (const char* k : {"youngs_modulus", "poisson_ratio", "motor_omega", "motor_gain"}) {
      if (r.has(k)) r.fail(k, fmt::format("only an elastic body (motion = \"elastic\") takes {}", k));
    }
  }
}

/// One [[body]] table (docs/contact.md).
BodyConfig read_body(io::TomlReader& r, std::size_t index, const SceneConfig& c) {
  const int ncomp = c.grid.geometry == Geometry::PlaneStrain ? 2 : 3;
  BodyConfig b;
  b.name = r.string_or("name", fmt::format("body{}", index));
  if (b.name == "grains" || b.name == "fluid" || b.name.empty()) {
    r.fail(
        "name",
        fmt::format("= \"{}\": body names must be non-empty and differ from the phases \"grains\", \"fluid\"", b.name));
  }
  if (!io::is_plain_name(b.name)) r.fail("name", fmt::format("= \"{}\": {}", b.name, io::kPlainNameRule));
  b.shape = parse_enum(r, "shape", BodyShape::Box, kBodyShapes);
  b.motion = parse_enum(r, "motion", BodyMotionKind::Prescribed, kMotions);
  read_body_shape(r, c, b);
  b.velocity_m_s = read_vec(r, "velocity", ncomp, {0, 0, 0}, false, c.grid.dim);
  if (auto speed = r.optional_number("speed")) {
    // speed [m/s] along the direction of `velocity` (then only a direction): --set v0=0.5
    r.require(*speed >= 0, "speed", *speed, "must be >= 0 [m/s] (the direction is given by velocity)");
    double n2 = 0.0;
    for (double v : b.velocity_m_s) n2 += v * v;
    if (!(n2 > 0)) r.fail("speed", "needs a non-zero `velocity` giving the direction of motion");
    for (double& v : b.velocity_m_s) v *= *speed / std::sqrt(n2);
  }
  if (b.shape == BodyShape::Cylinder && b.tilt_deg != 0.0) {  // an oblique launch along the tilted axis
    const double t = b.tilt_deg * M_PI / 180.0, vx = b.velocity_m_s[0], vz = b.velocity_m_s[2];
    b.velocity_m_s[0] = std::cos(t) * vx + std::sin(t) * vz;
    b.velocity_m_s[2] = -std::sin(t) * vx + std::cos(t) * vz;
  }
  if (r.has("ramp_time") && b.motion != BodyMotionKind::Prescribed)
    r.fail("ramp_time", "only a prescribed body (motion = \"prescribed\") takes a ramp_time");
  b.ramp_time_s = r.number_or("ramp_time", 0.0);
  r.require(b.ramp_time_s >= 0 && std::isfinite(b.ramp_time_s), "ramp_time", b.ramp_time_s,
            "must be >= 0 and finite [s]");
  b.points_per_cell = static_cast<int>(r.number_or("points_per_cell", 2));
  r.require(b.points_per_cell >= 1 && b.points_per_cell <= 8, "points_per_cell", b.points_per_cell,
            "must be an integer in [1, 8] (per axis)");
  b.friction = r.number_or("friction", 0.0);
  r.require(b.friction >= 0, "friction", b.friction, "must be >= 0 (Coulomb coefficient with the grains)");
  read_body_material(r, c, b);
  r.finish();
  return b;
}

/// [[body]]: solid third bodies (docs/contact.md) with distinct names; needs the grid and the
/// boundary (a body may cross a periodic pair of faces).
std::vector<BodyConfig> read_bodies(io::TomlReader& top, const SceneConfig& c) {
  auto bodies = top.table_array("body");
  std::vector<BodyConfig> out;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    out.push_back(read_body(bodies[i], i, c));
    for (std::size_t j = 0; j < i; ++j) {
      if (out[j].name == out[i].name) bodies[i].fail("name", fmt::format("= \"{}\" is used twice", out[i].name));
    }
  }
  return out;
}

/// [physics]: gravity [m/s^2] (default none).
std::array<double, 3> read_physics(io::TomlReader& top, const GridConfig& grid) {
  std::array<double, 3> gravity{0, 0, 0};
  if (auto ph = top.optional_table("physics")) {
    gravity = read_vec(*ph, "gravity", grid.dim, {0, 0, 0}, false);
    ph->finish();
  }
  return gravity;
}

/// [time]: duration, an optional fixed dt, the CFL fraction.
TimeConfig read_time(io::TomlReader& top) {
  io::TomlReader t = top.table("time");
  TimeConfig time;
  time.duration_s = t.number("duration");
  t.require(time.duration_s > 0 && std::isfinite(time.duration_s), "duration", time.duration_s, "must be positive [s]");
  time.dt_s = t.optional_number("dt");
  if (time.dt_s) t.require(*time.dt_s > 0, "dt", *time.dt_s, "must be positive [s]");
  time.cfl = t.number_or("cfl", time.cfl);
  t.require(time.cfl > 0 && time.cfl <= 1, "cfl", time.cfl, "must lie in (0, 1]");
  t.finish();
  return time;
}

/// [output]: frame and series intervals, checkpoints every so many steps.
OutputConfig read_output(io::TomlReader& top) {
  OutputConfig output;
  if (auto o = top.optional_table("output")) {
    output.frame_interval_s = o->number_or("frame_interval", 0.0);
    output.series_interval_s = o->number_or("series_interval", 0.0);
    const double ce = o->number_or("checkpoint_every", 0.0);
    o->require(output.frame_interval_s >= 0, "frame_interval", output.frame_interval_s, "must be >= 0 [s]");
    o->require(output.series_interval_s >= 0, "series_interval", output.series_interval_s, "must be >= 0 [s]");
    o->require(ce >= 0 && ce == std::floor(ce), "checkpoint_every", ce, "must be a whole number of steps >= 0");
    output.checkpoint_every = static_cast<long>(ce);
    o->finish();
  }
  return output;
}

/// analysis.snapshot_times: increasing times >= 0 [s], 2D grids only.
std::vector<double> read_snapshot_times(io::TomlReader& an, const GridConfig& grid) {
  std::vector<double> times;
  const toml::array* arr = an.raw("snapshot_times")->as_array();
  if (arr == nullptr) an.fail("snapshot_times", "must be an array of times [s]");
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const auto v = (*arr)[i].value<double>();
    if (!v) an.fail("snapshot_times", fmt::format("entry {} is not a number", i));
    an.require(*v >= 0, "snapshot_times", *v, "entries must be >= 0 [s] (times after the run's end are skipped)");
    if (i > 0) an.require(*v > times.back(), "snapshot_times", *v, "entries must increase");
    times.push_back(*v);
  }
  if (grid.dim != 2) an.fail("snapshot_times", "nodal-field snapshots are written for 2D grids only");
  return times;
}

/// The body of the intrusion, rod and wheel analyses (default: the first [[body]]) and whether the
/// set-up suits the kind; the other kinds take no body.
void check_analysis_body(io::TomlReader& an, const SceneConfig& c, AnalysisConfig& analysis) {
  const bool needs_body = analysis.kind == AnalysisKind::Intrusion || analysis.kind == AnalysisKind::Rod ||
                          analysis.kind == AnalysisKind::Wheel;
  if (!needs_body) {
    if (!analysis.body.empty()) an.fail("body", fmt::format("is only used by the intrusion, rod and wheel analyses"));
    return;
  }
  if (c.bodies.empty()) an.fail("kind", fmt::format("\"{}\" needs a [[body]]", to_string(analysis.kind)));
  if (analysis.body.empty()) analysis.body = c.bodies.front().name;
  const BodyConfig* target = nullptr;
  for (const auto& b : c.bodies)
    if (b.name == analysis.body) target = &b;
  if (target == nullptr) an.fail("body", fmt::format("= \"{}\": no [[body]] has that name", analysis.body));
  const bool axi = c.grid.geometry == Geometry::Axisymmetric;
  if (analysis.kind == AnalysisKind::Intrusion && !(axi && target->motion == BodyMotionKind::Prescribed)) {
    an.fail("kind", "\"intrusion\" needs an axisymmetric grid and a prescribed-velocity body");
  }
  if (analysis.kind == AnalysisKind::Rod && target->motion != BodyMotionKind::Free) {
    an.fail("kind", "\"rod\" needs a free rigid body (motion = \"free\")");
  }
  if (analysis.kind == AnalysisKind::Wheel &&
      !(c.grid.geometry != Geometry::Axisymmetric && target->motion == BodyMotionKind::Elastic)) {
    an.fail("kind", "\"wheel\" needs a plane-strain or 3D grid and an elastic body");
  }
}

/// [analysis]: the built-in measurement; needs the grid, boundary, bodies and duration read.
AnalysisConfig read_analysis(io::TomlReader& top, const SceneConfig& c) {
  AnalysisConfig analysis;
  auto an = top.optional_table("analysis");
  if (!an) return analysis;
  analysis.kind = parse_enum(*an, "kind", AnalysisKind::None, kAnalyses);
  analysis.average_from_s = an->number_or("average_from", 0.0);
  an->require(analysis.average_from_s >= 0 && analysis.average_from_s < c.time.duration_s, "average_from",
              analysis.average_from_s, "must lie in [0, time.duration) [s]");
  analysis.sample_interval_s = an->number_or("sample_interval", 0.0);
  an->require(analysis.sample_interval_s >= 0, "sample_interval", analysis.sample_interval_s, "must be >= 0 [s]");
  if (auto z = an->optional_number("sample_z")) analysis.sample_z_m = *z;
  if (analysis.kind == AnalysisKind::Annular &&
      (c.grid.geometry != Geometry::Axisymmetric || c.boundary[0].type != BoundaryType::Velocity)) {
    an->fail("kind", "\"annular\" needs an axisymmetric grid whose x_min face is a velocity wall (the bob)");
  }
  analysis.body = an->string_or("body", "");
  analysis.filter_window_s = an->number_or("filter_window", 0.0);
  an->require(analysis.filter_window_s >= 0, "filter_window", analysis.filter_window_s, "must be >= 0 [s]");
  analysis.front_fraction = an->number_or("front_fraction", 0.5);
  an->require(analysis.front_fraction > 0 && analysis.front_fraction < 1, "front_fraction", analysis.front_fraction,
              "must lie in (0, 1)");
  analysis.f_threshold = an->number_or("f_threshold", 0.5);
  an->require(analysis.f_threshold > 0 && analysis.f_threshold < 1, "f_threshold", analysis.f_threshold,
              "must lie in (0, 1)");
  if (an->has("snapshot_times")) analysis.snapshot_times_s = read_snapshot_times(*an, c.grid);
  check_analysis_body(*an, c, analysis);
  an->finish();
  return analysis;
}

/// [aliases]: short names for --set, string key paths.
std::map<std::string, std::string> read_aliases(const toml::table& root, const std::string& path) {
  std::map<std::string, std::string> aliases;
  if (const auto* al = root.get_as<toml::table>("aliases")) {
    for (const auto& [k, v] : *al) {
      if (!v.is_string())
        throw InputError(fmt::format("{}: key 'aliases.{}': must be a string key path", path, k.str()));
      aliases[std::string(k.str())] = *v.value<std::string>();
    }
  }
  return aliases;
}

/// [variants]: named bundles of overrides, `name = ["key=value", ...]` (keys as --set takes them,
/// aliases included), applied in their order by `--set name=true`; `--set name=false` applies
/// nothing. A variant may not share its name with an alias.
std::map<std::string, std::vector<std::string>> read_variants(const toml::table& root, const std::string& path,
                                                              const std::map<std::string, std::string>& aliases) {
  std::map<std::string, std::vector<std::string>> variants;
  const auto* vt = root.get_as<toml::table>("variants");
  if (vt == nullptr) return variants;
  for (const auto& [k, v] : *vt) {
    const std::string name(k.str());
    auto fail = [&](const std::string& why) {
      throw InputError(fmt::format("{}: key 'variants.{}': {}", path, name, why));
    };
    if (aliases.count(name) != 0) fail("is also an alias; give the variant another name");
    const auto* arr = v.as_array();
    if (arr == nullptr) fail("must be an array of \"key=value\" strings");
    auto& specs = variants[name];
    for (const auto& e : *arr) {
      const auto spec = e.value<std::string>();
      if (!spec || spec->find('=') == std::string::npos || spec->front() == '=')
        fail("must be an array of \"key=value\" strings");
      specs.push_back(*spec);
    }
  }
  return variants;
}

template <class E, std::size_t N>
const char* name_of(E e, const std::array<std::pair<const char*, E>, N>& names) {
  for (const auto& [n, v] : names) {
    if (v == e) return n;
  }
  return "?";
}

}  // namespace

CylinderFrame cylinder_frame(const BodyConfig& b) {
  CylinderFrame f;
  const double t = b.tilt_deg * M_PI / 180.0;
  f.axis = {std::sin(t), 0.0, std::cos(t)};
  f.base_m = {b.centre_m[0], b.centre_m[1], b.centre_m[2] + b.radius_m * std::fabs(std::sin(t))};
  for (int a = 0; a < 3; ++a) {
    const double top = f.base_m[a] + b.length_m * f.axis[a];
    const double rim = b.radius_m * std::sqrt(std::max(0.0, 1.0 - f.axis[a] * f.axis[a]));
    f.lo_m[a] = std::min(f.base_m[a], top) - rim;
    f.hi_m[a] = std::max(f.base_m[a], top) + rim;
  }
  return f;
}

const char* to_string(Geometry g) { return name_of(g, kGeometries); }
const char* to_string(ShapeKind s) { return name_of(s, kShapes); }
const char* to_string(BoundaryType b) { return name_of(b, kBoundaries); }
const char* to_string(Phase p) { return name_of(p, kPhases); }
const char* to_string(BodyMotionKind m) { return name_of(m, kMotions); }
const char* to_string(AnalysisKind k) { return name_of(k, kAnalyses); }

const std::array<const char*, 6>& face_names() {
  static const std::array<const char*, 6> n = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  return n;
}

SceneConfig load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  toml::table root = io::parse_toml_file(path);
  SceneConfig c;
  c.file = path;
  // Aliases first: they give --set its short names.
  c.aliases = read_aliases(root, path);
  const auto variants = read_variants(root, path, c.aliases);
  for (const auto& o : overrides) {
    const auto eq = o.find('=');
    const auto variant = eq == std::string::npos ? variants.end() : variants.find(o.substr(0, eq));
    if (variant == variants.end()) {
      apply_override(root, path, o, c.aliases);
      continue;
    }
    const std::string value = o.substr(eq + 1);
    if (value != "true" && value != "false") {
      throw InputError(
          fmt::format("--set {}: '{}' is a variant of {}: it takes true or false", o, variant->first, path));
    }
    if (value == "true")
      for (const auto& spec : variant->second) apply_override(root, path, spec, c.aliases);
  }
  {
    std::ostringstream resolved;
    resolved << root;
    c.resolved_toml = resolved.str();
  }
  io::TomlReader top(root, path);
  (void)top.optional_table("aliases");
  (void)top.optional_table("variants");
  // The sections in this order: each reader may use what the ones before it read (the bodies
  // the boundary, the analysis the bodies and the duration).
  read_scene(top, c);
  c.grid = read_grid(top);
  c.material = read_material(top, path);
  read_fluid(top, c);
  c.coupling = read_coupling(top);
  c.transfer = read_transfer(top);
  c.regions = read_regions(top, c.grid, c.material);
  c.boundary = read_boundary(top, path, c.grid);
  c.bodies = read_bodies(top, c);
  c.gravity_m_s2 = read_physics(top, c.grid);
  c.time = read_time(top);
  c.output = read_output(top);
  c.analysis = read_analysis(top, c);
  top.finish();
  return c;
}

}  // namespace oobleck::scene
