#include "oobleck/io/frames.hpp"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <unistd.h>

#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/detail/h5.hpp"
#include "oobleck/io/output_file.hpp"

namespace oobleck::io {
namespace fs = std::filesystem;

const char* xdmf_type_name(FieldType type) {
  switch (type) {
    case FieldType::scalar: return "Scalar";
    case FieldType::vector: return "Vector";
    case FieldType::sym_tensor: return "Tensor6";
    case FieldType::tensor: return "Tensor";
  }
  return "Scalar";
}

int stored_components(FieldType type) {
  switch (type) {
    case FieldType::scalar: return 1;
    case FieldType::vector: return 3;
    case FieldType::sym_tensor: return 6;
    case FieldType::tensor: return 9;
  }
  return 1;
}

bool is_plain_name(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

namespace {

void check_name(const std::string& name, const char* what) {
  if (!is_plain_name(name)) throw std::invalid_argument(fmt::format("{} name '{}': {}", what, name, kPlainNameRule));
}

/// Units: 1-64 printable ASCII characters ("m/s", "N s/rad", "1").
void check_units(const std::string& units, const std::string& owner) {
  const bool ok = !units.empty() && units.size() <= 64 &&
                  std::all_of(units.begin(), units.end(), [](char c) { return c >= ' ' && c <= '~'; });
  if (!ok)
    throw std::invalid_argument(fmt::format("{}: units '{}': use 1-64 printable ASCII characters", owner, units));
}

/// The dataset `name` under `loc` gets the string attribute `units`.
void write_units(hid_t loc, const std::string& name, const std::string& units) {
  h5::Handle d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT));
  h5::write_attribute(d.get(), "units", units);
}

std::vector<std::span<const double>> spans(std::initializer_list<std::span<const double>> list) {
  return std::vector<std::span<const double>>(list.begin(), list.end());
}

/// Interleave `parts` (one interleaved span of count×in_comps, or in_comps spans of count)
/// into count×out_comps values, padding missing components with zero.
std::vector<double> interleave(const std::vector<std::span<const double>>& parts, std::size_t count, int in_comps,
                               int out_comps) {
  const auto in = static_cast<std::size_t>(in_comps);
  const auto out = static_cast<std::size_t>(out_comps);
  std::vector<double> buf(count * out, 0.0);
  if (parts.size() == 1) {
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t c = 0; c < in; ++c) buf[i * out + c] = parts[0][i * in + c];
  } else {
    for (std::size_t c = 0; c < in; ++c)
      for (std::size_t i = 0; i < count; ++i) buf[i * out + c] = parts[c][i];
  }
  return buf;
}

std::string dims_text(const std::vector<std::uint64_t>& shape) {
  std::string s;
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ' ';
    s += std::to_string(shape[i]);
  }
  return s;
}

std::string hdf_item(const std::vector<std::uint64_t>& shape, const std::string& ref) {
  return fmt::format(R"(<DataItem Dimensions="{}" NumberType="Float" Precision="8" Format="HDF">{}</DataItem>)",
                     dims_text(shape), ref);
}

/// Where this process's items lie in a dataset's leading axes: (N) for points, (nz, ny, nx) for
/// the grid's nodes; `start` and `count` are this process's block of `shape` (all of it when it
/// writes alone).
struct Block {
  std::vector<std::uint64_t> shape, start, count;
  Block with_components(int out) const {
    Block b = *this;
    if (out > 1) {
      b.shape.push_back(static_cast<std::uint64_t>(out));
      b.start.push_back(0);
      b.count.push_back(static_cast<std::uint64_t>(out));
    }
    return b;
  }
};

/// Write one field under `loc` (this process's `count` items of `block`); append its XDMF
/// <Attribute> to `xml`.
void write_field(hid_t loc, const std::string& h5_prefix, const FieldView& f, std::size_t count, const Block& block,
                 std::string& xml, const std::string& indent) {
  const int out = stored_components(f.type);
  const Block full = block.with_components(out);
  const bool direct = f.parts.size() == 1 && f.components == out;
  std::vector<double> buf;
  const double* data = f.parts.empty() ? nullptr : f.parts[0].data();
  if (!direct) {
    buf = interleave(f.parts, count, f.components, out);
    data = buf.data();
  }
  const std::vector<std::uint64_t>& shape = full.shape;
  h5::write_dataset_part(loc, f.name, H5T_NATIVE_DOUBLE, shape, full.start, full.count, data);
  {
    h5::Handle d(H5Dopen2(loc, f.name.c_str(), H5P_DEFAULT));
    h5::write_attribute(d.get(), "type", std::string(xdmf_type_name(f.type)));
    h5::write_attribute(d.get(), "units", f.units);
  }
  xml += fmt::format("{}<Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n", indent, f.name,
                     xdmf_type_name(f.type));
  xml += fmt::format("{}  {}\n", indent, hdf_item(shape, h5_prefix + "/" + f.name));
  xml += fmt::format("{}</Attribute>\n", indent);
}

void check_fields(const FieldSet& set, const char* owner) {
  std::set<std::string> seen;
  for (const auto& f : set.fields()) {
    if (!seen.insert(f.name).second)
      throw std::invalid_argument(fmt::format("{}: field '{}' given twice", owner, f.name));
  }
}

const std::string kFramePrefix = "frame_";
const std::string kFrameSuffix = ".h5";
constexpr const char* kGridBlock = "grid";

}  // namespace

// ---------------------------------------------------------------------------------------------
// FieldSet

void FieldSet::add(FieldView field) {
  check_name(field.name, "field");
  check_units(field.units, fmt::format("field '{}'", field.name));
  if (field.name == "position") throw std::invalid_argument("field name 'position' is reserved for point positions");
  for (const auto& f : fields_) {
    if (f.name == field.name) throw std::invalid_argument(fmt::format("field '{}' given twice", field.name));
  }
  const auto comps = static_cast<std::size_t>(field.components);
  if (field.parts.size() == 1) {
    if (field.parts[0].size() != count_ * comps) {
      throw std::invalid_argument(fmt::format("field '{}': {} values given, expected {} items x {} components",
                                              field.name, field.parts[0].size(), count_, comps));
    }
  } else {
    if (field.parts.size() != comps) {
      throw std::invalid_argument(
          fmt::format("field '{}': {} component spans given, expected {}", field.name, field.parts.size(), comps));
    }
    for (const auto& p : field.parts) {
      if (p.size() != count_) {
        throw std::invalid_argument(
            fmt::format("field '{}': a component has {} values, expected {}", field.name, p.size(), count_));
      }
    }
  }
  fields_.push_back(std::move(field));
}

FieldSet& FieldSet::scalar(std::string name, std::span<const double> values, std::string units) {
  add({std::move(name), FieldType::scalar, 1, {values}, std::move(units)});
  return *this;
}

FieldSet& FieldSet::vector(std::string name, int components, std::span<const double> interleaved, std::string units) {
  if (components != 2 && components != 3) {
    throw std::invalid_argument(fmt::format("vector field '{}': {} components, expected 2 or 3", name, components));
  }
  add({std::move(name), FieldType::vector, components, {interleaved}, std::move(units)});
  return *this;
}

FieldSet& FieldSet::vector(std::string name, std::initializer_list<std::span<const double>> components,
                           std::string units) {
  const auto n = static_cast<int>(components.size());
  if (n != 2 && n != 3) {
    throw std::invalid_argument(fmt::format("vector field '{}': {} component spans, expected 2 or 3", name, n));
  }
  add({std::move(name), FieldType::vector, n, spans(components), std::move(units)});
  return *this;
}

FieldSet& FieldSet::sym_tensor(std::string name, std::span<const double> interleaved, std::string units) {
  add({std::move(name), FieldType::sym_tensor, 6, {interleaved}, std::move(units)});
  return *this;
}

FieldSet& FieldSet::sym_tensor(std::string name, std::initializer_list<std::span<const double>> components,
                               std::string units) {
  add({std::move(name), FieldType::sym_tensor, 6, spans(components), std::move(units)});
  return *this;
}

FieldSet& FieldSet::tensor(std::string name, std::span<const double> interleaved, std::string units) {
  add({std::move(name), FieldType::tensor, 9, {interleaved}, std::move(units)});
  return *this;
}

FieldSet& FieldSet::tensor(std::string name, std::initializer_list<std::span<const double>> components,
                           std::string units) {
  add({std::move(name), FieldType::tensor, 9, spans(components), std::move(units)});
  return *this;
}

// ---------------------------------------------------------------------------------------------
// PointCloud, NodeGrid

PointCloud::PointCloud(std::string name, int dim, std::span<const double> positions, std::string position_units)
    : FieldSet(dim > 0 ? positions.size() / static_cast<std::size_t>(dim) : 0),
      name_(std::move(name)),
      dim_(dim),
      position_units_(std::move(position_units)) {
  check_name(name_, "body");
  check_units(position_units_, fmt::format("body '{}': positions", name_));
  if (dim != 2 && dim != 3) throw std::invalid_argument(fmt::format("body '{}': dim {} is not 2 or 3", name_, dim));
  if (positions.size() % static_cast<std::size_t>(dim) != 0) {
    throw std::invalid_argument(
        fmt::format("body '{}': {} position values is not a multiple of dim {}", name_, positions.size(), dim));
  }
  positions_ = {positions};
}

PointCloud::PointCloud(std::string name, std::initializer_list<std::span<const double>> positions,
                       std::string position_units)
    : FieldSet(positions.size() > 0 ? positions.begin()->size() : 0),
      name_(std::move(name)),
      dim_(static_cast<int>(positions.size())),
      positions_(spans(positions)),
      position_units_(std::move(position_units)) {
  check_name(name_, "body");
  check_units(position_units_, fmt::format("body '{}': positions", name_));
  if (dim_ != 2 && dim_ != 3) {
    throw std::invalid_argument(fmt::format("body '{}': {} position spans, expected 2 or 3", name_, dim_));
  }
  for (const auto& p : positions_) {
    if (p.size() != count_)
      throw std::invalid_argument(fmt::format("body '{}': position spans differ in length", name_));
  }
}

NodeGrid::NodeGrid(int dim, std::array<double, 3> origin, std::array<double, 3> spacing,
                   std::array<std::size_t, 3> nodes)
    : FieldSet(nodes[0] * nodes[1] * nodes[2]),
      dim_(dim),
      origin_(origin),
      spacing_(spacing),
      nodes_(nodes),
      part_extent_(nodes) {
  if (dim != 2 && dim != 3) throw std::invalid_argument(fmt::format("grid: dim {} is not 2 or 3", dim));
  if (dim == 2 && nodes[2] != 1) throw std::invalid_argument("grid: a 2D grid needs nodes[2] = 1");
  for (int a = 0; a < dim; ++a) {
    if (!(spacing[static_cast<std::size_t>(a)] > 0.0)) throw std::invalid_argument("grid: spacing must be > 0");
  }
  if (dim == 2) {
    origin_[2] = 0.0;
    spacing_[2] = 1.0;
  }
}

void NodeGrid::set_part(std::array<std::size_t, 3> begin, std::array<std::size_t, 3> extent) {
  if (!fields_.empty()) throw std::invalid_argument("grid: set_part after fields were added");
  for (std::size_t a = 0; a < 3; ++a) {
    if (begin[a] + extent[a] > nodes_[a])
      throw std::invalid_argument(
          fmt::format("grid: part {}+{} of axis {} leaves its {} nodes", begin[a], extent[a], a, nodes_[a]));
  }
  part_begin_ = begin;
  part_extent_ = extent;
  count_ = extent[0] * extent[1] * extent[2];
}

// ---------------------------------------------------------------------------------------------
// FrameWriter

FrameWriter::FrameWriter(std::string run_dir, std::string name, Writers writers)
    : FrameWriter(std::move(run_dir), std::move(name), true, writers) {}

FrameWriter::FrameWriter(std::string run_dir, std::string name, bool fresh, Writers writers)
    : run_dir_(std::move(run_dir)),
      name_(std::move(name)),
      every_rank_(writers == Writers::every_rank && comm::size() > 1),
      indexer_(!every_rank_ || comm::is_root()) {
  check_name(name_, "frame series");
  if (!indexer_) return;
  std::error_code ec;
  if (!fs::is_directory(run_dir_, ec)) {
    throw InputError(fmt::format("output folder '{}' does not exist (frames cannot be written)", run_dir_));
  }
  check_writable(index_path(), "frames index");
  fs::create_directories(frame_dir(), ec);
  if (ec) throw InputError(fmt::format("cannot create frame folder '{}': {}", frame_dir(), ec.message()));
  for (const auto& e : fs::directory_iterator(frame_dir())) {
    const std::string f = e.path().filename().string();
    if (f.rfind(kFramePrefix, 0) != 0) continue;
    const bool frame = f.size() > kFrameSuffix.size() &&
                       f.compare(f.size() - kFrameSuffix.size(), kFrameSuffix.size(), kFrameSuffix) == 0;
    const bool temporary = f.find(kFrameSuffix + ".tmp-") != std::string::npos;  // left by a killed run
    if (temporary || (fresh && frame)) fs::remove(e.path(), ec);
  }
  if (fresh) fs::remove(index_path(), ec);
}

std::string FrameWriter::index_path() const { return (fs::path(run_dir_) / (name_ + ".xmf")).string(); }
std::string FrameWriter::frame_dir() const { return (fs::path(run_dir_) / name_).string(); }
std::string FrameWriter::frame_path(std::size_t index) const {
  return (fs::path(frame_dir()) / fmt::format("{}{:06d}{}", kFramePrefix, index, kFrameSuffix)).string();
}

FrameWriter FrameWriter::resume(std::string run_dir, std::int64_t last_step, std::string name, Writers writers) {
  FrameWriter w(std::move(run_dir), std::move(name), false, writers);
  if (!w.indexer_) {  // (rank 0 reads the series; the others only count its frames)
    w.entries_.resize(std::stoull(comm::broadcast({})));
    return w;
  }
  // Frame files are numbered consecutively from 0; stop at the first gap.
  std::size_t index = 0;
  for (;; ++index) {
    const std::string path = w.frame_path(index);
    if (!fs::exists(path)) break;
    h5::Handle file = h5::open_file_readonly(path);
    Entry e{};
    std::string blocks;
    bool ok = file.valid() && h5::read_attribute(file.get(), "step", e.step) &&
              h5::read_attribute(file.get(), "time", e.time) && h5::read_attribute(file.get(), "blocks", blocks);
    for (std::size_t pos = 0; ok && pos < blocks.size();) {
      const std::size_t end = std::min(blocks.find('\n', pos), blocks.size());
      const std::string block = blocks.substr(pos, end - pos);
      pos = end + 1;
      const std::string object = block == kGridBlock ? "/grid" : "/bodies/" + block;
      h5::Handle g(H5Gopen2(file.get(), object.c_str(), H5P_DEFAULT));
      std::string xml;
      ok = g.valid() && h5::read_attribute(g.get(), "xdmf", xml);
      e.blocks.emplace_back(block, std::move(xml));
    }
    if (!ok) {
      throw InputError(fmt::format("frame file '{}': not a readable oobleck frame (cannot resume its series)", path));
    }
    if (e.step > last_step) break;
    w.entries_.push_back(std::move(e));
  }
  // Frames after the restart point (and anything after a gap) belong to the abandoned future.
  for (std::error_code ec;; ++index) {
    const std::string path = w.frame_path(index);
    if (!fs::exists(path)) break;
    fs::remove(path, ec);
  }
  if (w.every_rank_) comm::broadcast(std::to_string(w.entries_.size()));
  w.write_index();
  return w;
}

namespace {

/// One body's group of a frame file (positions, vertex list, fields) and its XDMF grid block:
/// this process's b.count() points are points [first, first + count) of the body's `n`.
std::string write_body_block(hid_t bodies, const PointCloud& b, std::size_t first, std::size_t n,
                             const std::string& rel, const std::string& time_xml) {
  h5::Handle g = h5::create_group(bodies, b.name());
  const std::size_t mine = b.count();
  const Block points{{n}, {first}, {mine}};
  const Block xyz = points.with_components(b.dim());
  if (b.positions().size() == 1) {
    h5::write_dataset_part(g.get(), "position", H5T_NATIVE_DOUBLE, xyz.shape, xyz.start, xyz.count,
                           b.positions()[0].data());
  } else {
    const auto buf = interleave(b.positions(), mine, b.dim(), b.dim());
    h5::write_dataset_part(g.get(), "position", H5T_NATIVE_DOUBLE, xyz.shape, xyz.start, xyz.count, buf.data());
  }
  write_units(g.get(), "position", b.position_units());
  const std::vector<std::uint64_t>& pshape = xyz.shape;
  // Explicit vertex list 0..N-1: the Xdmf3 readers make no cells of a Polyvertex topology
  // without one (points then do not render); the XDMF (2) reader accepts it too.
  const bool small = n <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  if (small) {
    std::vector<std::int32_t> conn(mine);
    for (std::size_t i = 0; i < mine; ++i) conn[i] = static_cast<std::int32_t>(first + i);
    h5::write_dataset_part(g.get(), "connectivity", H5T_NATIVE_INT32, {n}, {first}, {mine}, conn.data());
  } else {
    std::vector<std::int64_t> conn(mine);
    for (std::size_t i = 0; i < mine; ++i) conn[i] = static_cast<std::int64_t>(first + i);
    h5::write_dataset_part(g.get(), "connectivity", H5T_NATIVE_INT64, {n}, {first}, {mine}, conn.data());
  }
  write_units(g.get(), "connectivity", "1");  // (point indices)
  h5::write_attribute(g.get(), "count", static_cast<std::int64_t>(n));
  std::string xml;
  const std::string prefix = fmt::format("{}:/bodies/{}", rel, b.name());
  xml += fmt::format("    <Grid Name=\"{}\" GridType=\"Uniform\">\n", b.name());
  xml += time_xml;
  xml += fmt::format("      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\">\n", n);
  xml += fmt::format(
      "        <DataItem Dimensions=\"{}\" NumberType=\"Int\" Precision=\"{}\" "
      "Format=\"HDF\">{}/connectivity</DataItem>\n",
      n, small ? 4 : 8, prefix);
  xml += "      </Topology>\n";
  xml += fmt::format("      <Geometry GeometryType=\"{}\">\n", b.dim() == 2 ? "XY" : "XYZ");
  xml += fmt::format("        {}\n", hdf_item(pshape, prefix + "/position"));
  xml += "      </Geometry>\n";
  for (const auto& f : b.fields()) write_field(g.get(), prefix, f, mine, points, xml, "      ");
  xml += "    </Grid>\n";
  h5::write_attribute(g.get(), "xdmf", xml);
  return xml;
}

/// The grid's group of a frame file (origin, spacing, nodal fields) and its XDMF grid block.
std::string write_grid_block(hid_t file, const NodeGrid& grid, const std::string& rel, const std::string& time_xml) {
  h5::Handle g = h5::create_group(file, "grid");
  const auto& o = grid.origin();
  const auto& h = grid.spacing();
  const auto& nn = grid.nodes();
  h5::write_attribute(g.get(), "origin", std::vector<double>{o[0], o[1], o[2]});
  h5::write_attribute(g.get(), "spacing", std::vector<double>{h[0], h[1], h[2]});
  h5::write_attribute(g.get(), "nodes",
                      std::vector<std::int64_t>{static_cast<std::int64_t>(nn[0]), static_cast<std::int64_t>(nn[1]),
                                                static_cast<std::int64_t>(nn[2])});
  h5::write_attribute(g.get(), "dim", static_cast<std::int64_t>(grid.dim()));
  // A 2D grid is written as one layer of a 3D mesh: VTK's XDMF readers place a
  // 2DCoRectMesh in the y-z plane, away from the XY points; a 3DCoRectMesh with nz = 1
  // lies in the x-y plane.
  const std::vector<std::uint64_t> lead{nn[2], nn[1], nn[0]};
  const auto& at = grid.part_begin();
  const auto& span = grid.part_extent();
  const Block nodes{lead, {at[2], at[1], at[0]}, {span[2], span[1], span[0]}};
  std::string xml;
  xml += fmt::format("    <Grid Name=\"{}\" GridType=\"Uniform\">\n", kGridBlock);
  xml += time_xml;
  xml += fmt::format("      <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{}\"/>\n", dims_text(lead));
  xml += "      <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n";
  xml += fmt::format(
      "        <DataItem Name=\"Origin\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
      "Format=\"XML\">{:.17g} {:.17g} {:.17g}</DataItem>\n",
      o[2], o[1], o[0]);
  xml += fmt::format(
      "        <DataItem Name=\"Spacing\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
      "Format=\"XML\">{:.17g} {:.17g} {:.17g}</DataItem>\n",
      h[2], h[1], h[0]);
  xml += "      </Geometry>\n";
  for (const auto& f : grid.fields()) write_field(g.get(), rel + ":/grid", f, grid.count(), nodes, xml, "      ");
  xml += "    </Grid>\n";
  h5::write_attribute(g.get(), "xdmf", xml);
  return xml;
}

}  // namespace

std::string FrameWriter::write(const Frame& frame) {
  const std::size_t index = entries_.size();
  std::string path = frame_path(index);
  const std::string rel = (fs::path(name_) / fs::path(path).filename()).string();  // relative to the .xmf

  std::set<std::string> body_names;
  for (const auto& b : frame.bodies) {
    if (b.name() == kGridBlock) throw std::invalid_argument("body name 'grid' is reserved for the grid");
    if (!body_names.insert(b.name()).second) {
      throw std::invalid_argument(fmt::format("frame {}: body '{}' given twice", index, b.name()));
    }
    check_fields(b, b.name().c_str());
  }
  if (frame.grid) check_fields(*frame.grid, "grid");

  // Each body's points on this process: [first, first + count) of its total (every rank: rank
  // order).
  std::vector<std::int64_t> mine;
  for (const auto& b : frame.bodies) mine.push_back(static_cast<std::int64_t>(b.count()));
  std::vector<std::size_t> first(mine.size(), 0), total(mine.begin(), mine.end());
  if (every_rank_) {
    const std::vector<std::int64_t> all = comm::all_gather(mine);
    for (std::size_t b = 0; b < mine.size(); ++b) {
      total[b] = 0;
      for (int r = 0; r < comm::size(); ++r) {
        const auto n = static_cast<std::size_t>(all[static_cast<std::size_t>(r) * mine.size() + b]);
        if (r < comm::rank()) first[b] += n;
        total[b] += n;
      }
    }
  }

  const std::string time_xml = fmt::format("      <Time Value=\"{:.17g}\"/>\n", frame.time);
  Entry entry{frame.step, frame.time, {}};
  std::string block_list;
  std::string tmp = fmt::format("{}.tmp-{}", path, ::getpid());
  if (every_rank_) tmp = comm::broadcast(tmp);  // (rank 0's name)
  try {
    h5::Handle file = h5::create_file(tmp, false, every_rank_);
    h5::write_attribute(file.get(), "time", frame.time);
    h5::write_attribute(file.get(), "step", frame.step);
    h5::write_attribute(file.get(), "format", std::string("oobleck-frame-1"));
    h5::Handle bodies = h5::create_group(file.get(), "bodies");
    for (std::size_t k = 0; k < frame.bodies.size(); ++k) {
      const PointCloud& b = frame.bodies[k];
      std::string xml = write_body_block(bodies.get(), b, first[k], total[k], rel, time_xml);
      // ParaView rejects a Polyvertex grid of zero points: an empty body stays in the HDF5 file
      // (so its fields are still listed) but not in the index of this frame.
      if (total[k] > 0) {
        entry.blocks.emplace_back(b.name(), std::move(xml));
        block_list += b.name() + "\n";
      }
    }
    if (frame.grid) {
      std::string xml = write_grid_block(file.get(), *frame.grid, rel, time_xml);
      entry.blocks.emplace_back(kGridBlock, std::move(xml));
      block_list += std::string(kGridBlock) + "\n";
    }
    h5::write_attribute(file.get(), "blocks", block_list);
    bodies.reset();
    if (!file.reset()) throw std::runtime_error("closing the file failed (disk full?)");
    if (indexer_) fs::rename(tmp, path);
  } catch (const std::exception& e) {
    std::error_code ec;
    if (indexer_) fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write frame file '{}': {}", path, e.what()));
  }
  entries_.push_back(std::move(entry));
  index_stale_ = true;
  const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - index_written_).count();
  if (index_bytes_ < kIndexAlwaysBytes || since >= 20.0 * index_seconds_) write_index();
  return path;
}

FrameWriter::FrameWriter(FrameWriter&& o) noexcept
    : run_dir_(std::move(o.run_dir_)),
      name_(std::move(o.name_)),
      every_rank_(o.every_rank_),
      indexer_(o.indexer_),
      entries_(std::move(o.entries_)),
      index_stale_(o.index_stale_),
      index_bytes_(o.index_bytes_),
      index_seconds_(o.index_seconds_),
      index_written_(o.index_written_) {
  o.index_stale_ = false;
}

FrameWriter& FrameWriter::operator=(FrameWriter&& o) noexcept {
  if (this != &o) {
    try {
      flush();
    } catch (...) {
    }
    run_dir_ = std::move(o.run_dir_);
    name_ = std::move(o.name_);
    every_rank_ = o.every_rank_;
    indexer_ = o.indexer_;
    entries_ = std::move(o.entries_);
    index_stale_ = o.index_stale_;
    index_bytes_ = o.index_bytes_;
    index_seconds_ = o.index_seconds_;
    index_written_ = o.index_written_;
    o.index_stale_ = false;
  }
  return *this;
}

FrameWriter::~FrameWriter() {
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; the index then lists the frames up to its last rewrite.
  }
}

void FrameWriter::flush() {
  if (index_stale_) write_index();
}

void FrameWriter::write_index() {
  if (!indexer_) {
    index_stale_ = false;
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  // One temporal collection per block (body or grid), in order of first appearance: ParaView
  // then shows one block per body with the same name at every time.
  std::vector<std::string> order;
  for (const auto& e : entries_)
    for (const auto& [block, xml] : e.blocks)
      if (std::find(order.begin(), order.end(), block) == order.end()) order.push_back(block);
  std::string s;
  s += "<?xml version=\"1.0\" ?>\n";
  s += "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n";
  s += "<Xdmf Version=\"2.0\">\n";
  s += "<Domain>\n";
  for (const auto& block : order) {
    s += fmt::format("  <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", block);
    for (const auto& e : entries_)
      for (const auto& [b, xml] : e.blocks)
        if (b == block) s += xml;
    s += "  </Grid>\n";
  }
  s += "</Domain>\n";
  s += "</Xdmf>\n";
  write_file_atomically(index_path(), s, "frames index");
  index_written_ = std::chrono::steady_clock::now();
  index_seconds_ = std::chrono::duration<double>(index_written_ - start).count();
  index_bytes_ = s.size();
  index_stale_ = false;
}

}  // namespace oobleck::io
