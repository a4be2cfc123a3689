#pragma once
// Run frames for ParaView: HDF5 heavy data, one file per frame, plus one XDMF (.xmf) index.
//
// Layout of a run folder (see docs/output.md):
//   RUN/frames.xmf                 XDMF 2 index, rewritten atomically after every frame, so a
//                                  run killed at any moment leaves an index that opens
//   RUN/frames/frame_000000.h5     one self-contained HDF5 file per frame, written to a temporary
//   RUN/frames/frame_000001.h5     name and renamed: a frame file is complete or absent
//
// One file per frame (rather than one growing file) because a crash while writing can then only
// lose the frame being written; HDF5 files that are open for writing when a process dies are
// often unreadable as a whole.
//
// The index holds one temporal collection per block (each body, and "grid"), each a list of
// Uniform grids with their Time, so ParaView shows one block per body under the same name at
// every time step.
//
// Inside a frame file:
//   /                    attributes: time (double), step (int64), format "oobleck-frame-1",
//                                    blocks (names of the blocks in the index, one per line)
//   /bodies/NAME/position          (N, dim) double, dim = 2 or 3
//   /bodies/NAME/connectivity      (N) int32 0..N-1 (int64 above 2^31 points): Polyvertex cells
//   /bodies/NAME/FIELD             (N) scalar, (N, 3) vector, (N, 6) tensor6, (N, 9) tensor
//   /grid/FIELD                    (nz, ny, nx[, c]) node values, x fastest; nz = 1 in 2D
//   /grid                          attributes: origin, spacing (x, y, z order), nodes (nx, ny, nz)
//   /bodies/NAME, /grid            attribute xdmf: the block's <Grid> element (used on resume)
// Every field dataset carries an attribute `type` = Scalar | Vector | Tensor6 | Tensor, and every
// dataset (position and connectivity included) a string attribute `units`: the field's unit as
// given ("m", "m/s", "Pa", "kg/rad", "1" for dimensionless; position: the cloud's position units,
// connectivity: "1").
//
// The writer depends on nothing but spans of doubles, so it serves any solver layout:
// interleaved arrays (x0 y0 x1 y1 ...) or structure of arrays (one span per component).
//
// In a decomposed run every rank writes the frame file together (Writers::every_rank, parallel
// HDF5): each gives its own points and its own block of the grid's nodes; the file holds every
// rank's points in rank order, as one dataset per field, and reads as a one-rank run's does.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "oobleck/io/writers.hpp"

namespace oobleck::io {

/// Names of bodies and fields become HDF5 groups and datasets (and scene names run folders):
/// 1–64 letters, digits, '_', '-', '.'.
bool is_plain_name(const std::string& name);
inline constexpr const char* kPlainNameRule = "use 1-64 characters of letters, digits, '_', '-', '.'";

/// XDMF attribute types. Vectors are stored with 3 components (2-component input gets a zero
/// third component, which ParaView expects for glyphs and the Calculator); symmetric tensors
/// with 6 in XDMF Tensor6 order (xx, xy, xz, yy, yz, zz); full tensors with 9, row-major
/// (xx, xy, xz, yx, yy, yz, zx, zy, zz).
enum class FieldType { scalar, vector, sym_tensor, tensor };

/// "Scalar", "Vector", "Tensor6", "Tensor" (the XDMF AttributeType).
const char* xdmf_type_name(FieldType type);
/// Components stored per item: 1, 3, 6, 9.
int stored_components(FieldType type);

/// A read-only view of one named field: either one interleaved span (count × input components)
/// or one span per input component (each of length count). The data must stay alive until
/// FrameWriter::write returns.
struct FieldView {
  std::string name;
  FieldType type = FieldType::scalar;
  int components = 1;  ///< input components per item (vectors: 2 or 3)
  std::vector<std::span<const double>> parts;
  std::string units;  ///< the `units` attribute of its dataset ("m/s", "Pa", "1" dimensionless)
};

/// Named fields over `count` items (points of a body, nodes of a grid), each with its units.
/// Names are 1–64 characters of [A-Za-z0-9_.-] and unique; units are 1–64 printable ASCII
/// characters ("1" for dimensionless); sizes are checked against count. Violations are
/// programming errors: std::invalid_argument naming the field.
class FieldSet {
 public:
  explicit FieldSet(std::size_t count) : count_(count) {}
  std::size_t count() const { return count_; }
  const std::vector<FieldView>& fields() const { return fields_; }

  FieldSet& scalar(std::string name, std::span<const double> values, std::string units);
  /// 2 or 3 components per item, interleaved.
  FieldSet& vector(std::string name, int components, std::span<const double> interleaved, std::string units);
  /// 2 or 3 spans, one per component.
  FieldSet& vector(std::string name, std::initializer_list<std::span<const double>> components, std::string units);
  /// 6 values per item, interleaved, order xx xy xz yy yz zz.
  FieldSet& sym_tensor(std::string name, std::span<const double> interleaved, std::string units);
  /// 6 spans in the order xx xy xz yy yz zz.
  FieldSet& sym_tensor(std::string name, std::initializer_list<std::span<const double>> components, std::string units);
  /// 9 values per item, interleaved, row-major.
  FieldSet& tensor(std::string name, std::span<const double> interleaved, std::string units);
  /// 9 spans, row-major.
  FieldSet& tensor(std::string name, std::initializer_list<std::span<const double>> components, std::string units);

  // A field is a view of its values, which must outlive the write: a temporary vector would
  // dangle, so passing one does not compile.
  FieldSet& scalar(std::string name, std::vector<double>&& values, std::string units) = delete;
  FieldSet& vector(std::string name, int components, std::vector<double>&& interleaved, std::string units) = delete;
  FieldSet& sym_tensor(std::string name, std::vector<double>&& interleaved, std::string units) = delete;
  FieldSet& tensor(std::string name, std::vector<double>&& interleaved, std::string units) = delete;

 protected:
  void add(FieldView field);
  std::size_t count_;
  std::vector<FieldView> fields_;
};

/// The points of one body: positions (in `position_units`, metres unless given) plus any fields
/// (shown as a Polyvertex grid in ParaView).
class PointCloud : public FieldSet {
 public:
  /// `dim` = 2 or 3; `positions` interleaved, its size a multiple of dim.
  PointCloud(std::string name, int dim, std::span<const double> positions, std::string position_units = "m");
  /// Positions as 2 or 3 spans (x, y[, z]) of equal length.
  PointCloud(std::string name, std::initializer_list<std::span<const double>> positions,
             std::string position_units = "m");
  const std::string& name() const { return name_; }
  int dim() const { return dim_; }
  const std::vector<std::span<const double>>& positions() const { return positions_; }
  const std::string& position_units() const { return position_units_; }

 private:
  std::string name_;
  int dim_;
  std::vector<std::span<const double>> positions_;
  std::string position_units_;
};

/// A uniform Cartesian grid of nodes: node (i, j, k) sits at origin + (i dx, j dy, k dz); node
/// fields are indexed i + nx (j + ny k) (x fastest). In 2D nodes[2] must be 1.
class NodeGrid : public FieldSet {
 public:
  NodeGrid(int dim, std::array<double, 3> origin, std::array<double, 3> spacing, std::array<std::size_t, 3> nodes);
  int dim() const { return dim_; }
  const std::array<double, 3>& origin() const { return origin_; }
  const std::array<double, 3>& spacing() const { return spacing_; }
  const std::array<std::size_t, 3>& nodes() const { return nodes_; }

  /// The fields added after this call hold only the box of nodes that starts at node `begin`
  /// and spans `extent` nodes per axis (x fastest): this rank's part of a grid that every rank
  /// writes (Writers::every_rank). Without it they hold every node. std::invalid_argument when
  /// fields were added already or the box leaves the grid.
  void set_part(std::array<std::size_t, 3> begin, std::array<std::size_t, 3> extent);
  const std::array<std::size_t, 3>& part_begin() const { return part_begin_; }
  const std::array<std::size_t, 3>& part_extent() const { return part_extent_; }

 private:
  int dim_;
  std::array<double, 3> origin_, spacing_;
  std::array<std::size_t, 3> nodes_, part_begin_{0, 0, 0}, part_extent_;
};

struct Frame {
  double time = 0.0;
  std::int64_t step = 0;
  std::vector<PointCloud> bodies;
  std::optional<NodeGrid> grid;
};

/// Writes frames into a run folder and keeps its XDMF index valid after every frame.
class FrameWriter {
 public:
  /// Start a new series `name` ("frames") in `run_dir`, which must exist (InputError
  /// otherwise). Frame files of an earlier series with the same name (RUN/NAME/frame_*.h5) and
  /// its index are removed, so a reused output folder never mixes two runs.
  /// Writers::every_rank: made on every rank of a decomposed run, whose write() calls are then
  /// collective (rank 0 alone checks and cleans the folder and writes the index).
  explicit FrameWriter(std::string run_dir, std::string name = "frames", Writers writers = Writers::one);

  /// Continue a series after a restart from step `last_step`: frames with step <= last_step are
  /// kept (their index entries are rebuilt from the frame files), later ones are deleted.
  /// Unreadable frame files (a crash mid-write leaves none, but a damaged disk might) are an
  /// InputError naming the file.
  static FrameWriter resume(std::string run_dir, std::int64_t last_step, std::string name = "frames",
                            Writers writers = Writers::one);

  FrameWriter(FrameWriter&& other) noexcept;
  FrameWriter& operator=(FrameWriter&& other) noexcept;
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;
  /// Brings the index up to date (flush()), reporting nothing on failure.
  ~FrameWriter();

  /// Write one frame file and rewrite the index. Returns the frame file's path. Every rank: each
  /// passes its own points (and part of the grid, NodeGrid::set_part), the same bodies and fields. Failures while
  /// writing (disk full) throw std::runtime_error naming the file; the index still lists every
  /// frame written before.
  ///
  /// The index is rewritten whole (and atomically) after every frame while it is under
  /// `kIndexAlwaysBytes`; a longer index (hundreds of frames) is rewritten only when the time
  /// since its last rewrite is at least 20 times what that rewrite took, which bounds its cost
  /// to ~5% of the run instead of growing quadratically. It is then always valid but may lag
  /// the newest frames by a few seconds' worth; flush() and the destructor complete it.
  std::string write(const Frame& frame);

  /// Rewrite the index now if frames were written since its last rewrite.
  void flush();
  static constexpr std::size_t kIndexAlwaysBytes = std::size_t{1} << 20;

  std::size_t frames_written() const { return entries_.size(); }
  std::string index_path() const;
  std::string frame_dir() const;
  /// Path of frame number `index` (0-based).
  std::string frame_path(std::size_t index) const;

 private:
  struct Entry {
    std::int64_t step;
    double time;
    std::vector<std::pair<std::string, std::string>> blocks;  // (body or "grid", its <Grid> element)
  };
  FrameWriter(std::string run_dir, std::string name, bool fresh, Writers writers);
  void write_index();

  std::string run_dir_, name_;
  bool every_rank_ = false;     // (Writers::every_rank in a decomposed run)
  bool indexer_ = true;         // this process handles the folder and the index (rank 0)
  std::vector<Entry> entries_;  // (on the other ranks of every_rank_ only their number counts)
  bool index_stale_ = false;
  std::size_t index_bytes_ = 0;
  double index_seconds_ = 0.0;                           // duration of the last rewrite
  std::chrono::steady_clock::time_point index_written_;  // when it ended
};

}  // namespace oobleck::io
