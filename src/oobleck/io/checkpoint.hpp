#pragma once
// Checkpoints: named arrays (double, int64, uint8) with shapes plus scalar attributes (step,
// time, the resolved configuration text, any others) in one HDF5 file, for restarts that
// continue bit for bit.
//
//   /            attributes: format "oobleck-checkpoint-1", step, time, config, and the extra
//                attributes (real_*, int_*, text_* prefixes keep their kinds apart)
//   /arrays/NAME dataset of the array's type and shape; attribute `checksum` (FNV-1a 64 of the
//                raw bytes, as int64) detects damaged data that HDF5 itself would not notice. An
//                array that the ranks of a decomposed run wrote together has instead
//                `block_checksums` (FNV-1a 64 of each rank's block, in rank order) and
//                `block_values` (the values in each block); attribute `units` when the writer
//                gave them (a run gives every array's: "m", "kg/rad", "1")
//
// Names may contain '/' to group arrays ("grains/velocity"). Values are written in the native
// representation and read back without conversion: the round trip is bit-exact (NaN payloads
// and signed zeros included). Writing goes to a temporary file renamed over the target on
// commit(), so a crash never leaves a half-written checkpoint under the final name.
//
// Decomposed runs (Writers::every_rank): every rank makes the writer and the same calls; the
// per-point arrays (ranks_array) are written together with parallel HDF5, each rank its own
// points; attributes and the other arrays are rank 0's, which it adds alone on commit().
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "oobleck/io/writers.hpp"

namespace oobleck::io {

/// Streams arrays into a new checkpoint file without copying them.
class CheckpointWriter {
 public:
  /// Opens `path` + ".tmp-PID" for writing; InputError when the folder is missing or read-only.
  /// Writers::every_rank: made on every rank of a decomposed run (collective).
  explicit CheckpointWriter(std::string path, Writers writers = Writers::one);
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;
  ~CheckpointWriter();  // removes the temporary file unless committed

  void set_step(std::int64_t step);
  void set_time(double time);
  void set_config(const std::string& resolved_configuration);
  /// Extra scalar attributes (e.g. "dt", "rng_state"). Names: [A-Za-z0-9_.-]+.
  void attribute(const std::string& name, double value);
  void attribute(const std::string& name, std::int64_t value);
  void attribute(const std::string& name, const std::string& value);

  /// Store `data` under `name` with `shape` (empty: one dimension of data.size()). The product
  /// of the shape must equal data.size() (std::invalid_argument otherwise); names are unique.
  /// `units` not empty: the dataset's string attribute `units`.
  void array(const std::string& name, std::span<const double> data, std::vector<std::uint64_t> shape = {},
             const std::string& units = {});
  void array(const std::string& name, std::span<const std::int64_t> data, std::vector<std::uint64_t> shape = {},
             const std::string& units = {});
  void array(const std::string& name, std::span<const std::uint8_t> data, std::vector<std::uint64_t> shape = {},
             const std::string& units = {});

  /// Store under `name` every rank's `data` concatenated in rank order (one dimension): the
  /// points of a decomposed run, written by every rank at once. One writer: array(name, data).
  void ranks_array(const std::string& name, std::span<const double> data, const std::string& units = {});
  void ranks_array(const std::string& name, std::span<const std::uint8_t> data, const std::string& units = {});

  /// Close and atomically rename to the target path. Throws std::runtime_error when the file
  /// cannot be completed (disk full); the previous checkpoint at `path`, if any, is then kept.
  /// Every rank: returns once rank 0 has renamed the file.
  void commit();
  const std::string& path() const { return path_; }

  struct Impl;  // HDF5 handles (defined in checkpoint.cpp)

 private:
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

/// A checkpoint read back into memory. Accessors throw InputError naming the file and the array
/// when it is missing or of another type.
class Checkpoint {
 public:
  using Data = std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::uint8_t>>;
  struct Array {
    std::vector<std::uint64_t> shape;
    Data data;
  };

  const std::string& file() const { return file_; }
  std::int64_t step() const { return step_; }
  double time() const { return time_; }
  const std::string& config() const { return config_; }

  bool has(const std::string& name) const { return arrays_.count(name) > 0; }
  std::vector<std::string> names() const;
  const std::vector<std::uint64_t>& shape(const std::string& name) const;
  const std::vector<double>& doubles(const std::string& name) const;
  const std::vector<std::int64_t>& int64s(const std::string& name) const;
  const std::vector<std::uint8_t>& bytes(const std::string& name) const;
  /// Copy array `name` into `out`, whose size must match (InputError otherwise): restores state
  /// into arrays the solver already owns.
  void read_into(const std::string& name, std::span<double> out) const;
  void read_into(const std::string& name, std::span<std::int64_t> out) const;
  void read_into(const std::string& name, std::span<std::uint8_t> out) const;

  double real_attribute(const std::string& name) const;
  std::int64_t int_attribute(const std::string& name) const;
  const std::string& text_attribute(const std::string& name) const;

 private:
  friend Checkpoint read_checkpoint(const std::string& path);
  const Array& get(const std::string& name) const;
  std::string file_;
  std::int64_t step_ = 0;
  double time_ = 0.0;
  std::string config_;
  std::map<std::string, Array> arrays_;
  std::map<std::string, double> reals_;
  std::map<std::string, std::int64_t> ints_;
  std::map<std::string, std::string> texts_;
};

/// Read a whole checkpoint. InputError "checkpoint '<path>': <reason>" when the file is missing,
/// not HDF5, not an oobleck checkpoint, truncated, or an array fails its checksum.
Checkpoint read_checkpoint(const std::string& path);

}  // namespace oobleck::io
