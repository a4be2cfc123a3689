#pragma once
// Internal helpers over the HDF5 C API shared by frames.cpp and checkpoint.cpp. Not a public
// header: HDF5 is a PRIVATE dependency of oobleck_lib, so only .cpp files of src/oobleck/io
// include this.
#include <cstdint>
#include <string>
#include <vector>

#include <hdf5.h>

namespace oobleck::io::h5 {

/// Owns one HDF5 identifier (file, group, dataset, dataspace, type, attribute, property list)
/// and closes it with the matching H5*close.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Close now; returns false when HDF5 reports an error (e.g. a failed flush on file close).
  bool reset();

 private:
  hid_t id_ = H5I_INVALID_HID;
};

/// Silence HDF5's automatic error printing on stderr (the library turns failures into
/// exceptions with their own messages). Idempotent.
void silence_errors();

/// The innermost message of HDF5's error stack, or "" (for error reports).
std::string last_error();

/// Create (truncate) a file. Throws std::runtime_error naming `path` on failure.
/// `large_attributes` selects the HDF5 1.8+ file format, whose dense attribute storage lifts
/// the 64 KiB limit on one object's attributes (used by checkpoints for the configuration text).
/// `every_rank`: every MPI rank creates the file together (parallel HDF5, MPI-IO); each then
/// makes the same calls for groups, datasets and attributes, with the same values, and writes
/// its own block of each dataset (write_dataset_part); closing is collective too. Only in a
/// decomposed run (comm::size() > 1) of a build with MPI.
Handle create_file(const std::string& path, bool large_attributes = false, bool every_rank = false);
/// Open a file read-only; returns an invalid handle when it cannot be opened.
Handle open_file_readonly(const std::string& path);
/// Open an existing file for writing by this process alone; throws std::runtime_error naming it.
Handle open_file_readwrite(const std::string& path, bool large_attributes = false);
/// Whether every rank writes the file that `loc` belongs to (create_file's `every_rank`).
bool written_by_every_rank(hid_t loc);

Handle create_group(hid_t loc, const std::string& name);

/// A dataset of `shape` of which this process writes the block that starts at `start` and spans
/// `count` (one entry per axis; `data` holds the block, last axis fastest). In a file that every
/// rank writes, every rank calls it with the same name and shape (the write is collective; a
/// rank without values passes a zero count); otherwise start = 0 and count = shape write all.
/// `link_properties`: H5Dcreate2's link creation list (e.g. one that creates missing groups).
void write_dataset_part(hid_t loc, const std::string& name, hid_t type, const std::vector<std::uint64_t>& shape,
                        const std::vector<std::uint64_t>& start, const std::vector<std::uint64_t>& count,
                        const void* data, hid_t link_properties = H5P_DEFAULT);

void write_attribute(hid_t loc, const std::string& name, double value);
void write_attribute(hid_t loc, const std::string& name, std::int64_t value);
void write_attribute(hid_t loc, const std::string& name, const std::string& value);
void write_attribute(hid_t loc, const std::string& name, const std::vector<double>& values);
void write_attribute(hid_t loc, const std::string& name, const std::vector<std::int64_t>& values);

bool has_attribute(hid_t loc, const std::string& name);
/// Readers return false when the attribute is absent or of the wrong kind.
bool read_attribute(hid_t loc, const std::string& name, double& value);
bool read_attribute(hid_t loc, const std::string& name, std::int64_t& value);
bool read_attribute(hid_t loc, const std::string& name, std::string& value);
bool read_attribute(hid_t loc, const std::string& name, std::vector<std::int64_t>& values);

}  // namespace oobleck::io::h5
