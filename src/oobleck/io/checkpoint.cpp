#include "oobleck/io/checkpoint.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
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

namespace {

constexpr const char* kFormat = "oobleck-checkpoint-1";

constexpr std::uint64_t kFnvOffsetBasis = 14695981039346656037ULL;  // FNV-1a 64
/// The offset basis of the whole-array checksums of older checkpoints (a digit short of FNV's),
/// still accepted on reading.
constexpr std::uint64_t kOlderOffsetBasis = 1469598103934665603ULL;

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t basis = kFnvOffsetBasis) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = basis;
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

std::int64_t as_int64(std::uint64_t v) {
  std::int64_t out;
  std::memcpy(&out, &v, sizeof out);
  return out;
}

bool plain_name(const std::string& name, bool allow_slash) {
  if (name.empty() || name.size() > 200 || name.front() == '/' || name.back() == '/') return false;
  if (name.find("//") != std::string::npos) return false;
  return std::all_of(name.begin(), name.end(), [&](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.' || (allow_slash && c == '/');
  });
}

void check_attribute_name(const std::string& name) {
  if (!plain_name(name, false)) {
    throw std::invalid_argument(
        fmt::format("checkpoint attribute name '{}': use letters, digits, '_', '-', '.'", name));
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Writer

struct CheckpointWriter::Impl {
  std::string tmp;
  h5::Handle file, arrays, lcpl;
  std::set<std::string> names;
  std::string name_list;
  bool committed = false;
  bool every_rank = false;  // (Writers::every_rank in a decomposed run)
  bool root = true;         // this process renames the file (rank 0)
  /// Every rank: rank 0's attributes and arrays, written by it alone on commit() (its arguments:
  /// the file and the /arrays group).
  std::vector<std::function<void(hid_t, hid_t)>> later;

  /// Write to the file now, or (every rank) on rank 0 at commit().
  void put(std::function<void(hid_t, hid_t)> write) {
    if (!every_rank) {
      write(file.get(), arrays.get());
    } else if (root) {
      later.push_back(std::move(write));
    }
  }
};

CheckpointWriter::CheckpointWriter(std::string path, Writers writers)
    : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
  check_writable(path_, "checkpoint");
  impl_->every_rank = writers == Writers::every_rank && comm::size() > 1;
  impl_->root = !impl_->every_rank || comm::is_root();
  impl_->tmp = fmt::format("{}.tmp-{}", path_, ::getpid());
  if (impl_->every_rank) impl_->tmp = comm::broadcast(impl_->tmp);  // (rank 0's name)
  try {
    impl_->file = h5::create_file(impl_->tmp, true, impl_->every_rank);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("checkpoint '{}': {}", path_, e.what()));
  }
  impl_->arrays = h5::create_group(impl_->file.get(), "arrays");
  impl_->lcpl = h5::Handle(H5Pcreate(H5P_LINK_CREATE));
  H5Pset_create_intermediate_group(impl_->lcpl.get(), 1);
  impl_->put([](hid_t file, hid_t) {
    h5::write_attribute(file, "format", std::string(kFormat));
    h5::write_attribute(file, "step", std::int64_t{0});
    h5::write_attribute(file, "time", 0.0);
    h5::write_attribute(file, "config", std::string());
  });
}

CheckpointWriter::~CheckpointWriter() {
  if (impl_ && !impl_->committed) {
    impl_->arrays.reset();
    impl_->lcpl.reset();
    impl_->file.reset();
    std::error_code ec;
    if (impl_->root) fs::remove(impl_->tmp, ec);
  }
}

void CheckpointWriter::set_step(std::int64_t step) {
  impl_->put([step](hid_t file, hid_t) { h5::write_attribute(file, "step", step); });
}
void CheckpointWriter::set_time(double time) {
  impl_->put([time](hid_t file, hid_t) { h5::write_attribute(file, "time", time); });
}
void CheckpointWriter::set_config(const std::string& resolved_configuration) {
  impl_->put(
      [resolved_configuration](hid_t file, hid_t) { h5::write_attribute(file, "config", resolved_configuration); });
}

namespace {
template <class T>
void put_attribute(CheckpointWriter::Impl& impl, const std::string& name, const T& value) {
  check_attribute_name(name);
  impl.put([name, value](hid_t file, hid_t) { h5::write_attribute(file, name, value); });
}
}  // namespace

void CheckpointWriter::attribute(const std::string& name, double value) {
  put_attribute(*impl_, "real_" + name, value);
}
void CheckpointWriter::attribute(const std::string& name, std::int64_t value) {
  put_attribute(*impl_, "int_" + name, value);
}
void CheckpointWriter::attribute(const std::string& name, const std::string& value) {
  put_attribute(*impl_, "text_" + name, value);
}

namespace {
/// Check a new array's name (plain, unused) and that `shape` (empty: one dimension) holds its
/// `values`; returns the shape and adds the name to the list.
std::vector<std::uint64_t> new_array(CheckpointWriter::Impl& impl, const std::string& path, const std::string& name,
                                     std::size_t values, std::vector<std::uint64_t> shape) {
  if (impl.committed) throw std::logic_error(fmt::format("checkpoint '{}': array '{}' after commit()", path, name));
  if (!plain_name(name, true)) {
    throw std::invalid_argument(
        fmt::format("checkpoint array name '{}': use letters, digits, '_', '-', '.', '/' between parts", name));
  }
  if (impl.names.count(name) > 0) {
    throw std::invalid_argument(fmt::format("checkpoint '{}': array '{}' written twice", path, name));
  }
  if (shape.empty()) shape = {values};
  std::uint64_t count = 1;
  for (auto n : shape) count *= n;
  if (count != values) {
    throw std::invalid_argument(
        fmt::format("checkpoint array '{}': shape holds {} values but {} were given", name, count, values));
  }
  impl.names.insert(name);
  impl.name_list += name + "\n";
  return shape;
}

template <class T>
void write_array(CheckpointWriter::Impl& impl, const std::string& path, const std::string& name, hid_t type,
                 std::span<const T> data, std::vector<std::uint64_t> shape, const std::string& units) {
  shape = new_array(impl, path, name, data.size(), std::move(shape));
  auto write = [&impl, path, name, type, shape, units](hid_t, hid_t arrays, std::span<const T> values) {
    try {
      h5::write_dataset_part(arrays, name, type, shape, std::vector<std::uint64_t>(shape.size(), 0), shape,
                             values.data(), impl.lcpl.get());
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("checkpoint '{}': {}", path, e.what()));
    }
    h5::Handle dset(H5Dopen2(arrays, name.c_str(), H5P_DEFAULT));
    h5::write_attribute(dset.get(), "checksum", as_int64(fnv1a(values.data(), values.size_bytes())));
    if (!units.empty()) h5::write_attribute(dset.get(), "units", units);
  };
  if (!impl.every_rank) {
    write(impl.file.get(), impl.arrays.get(), data);
  } else if (impl.root) {  // (rank 0's values, kept until commit())
    impl.put([write, copy = std::vector<T>(data.begin(), data.end())](hid_t file, hid_t arrays) {
      write(file, arrays, copy);
    });
  }
}

template <class T>
void write_ranks_array(CheckpointWriter::Impl& impl, const std::string& path, const std::string& name, hid_t type,
                       std::span<const T> data, const std::string& units) {
  if (!impl.every_rank) return write_array(impl, path, name, type, data, {}, units);
  new_array(impl, path, name, data.size(), {data.size()});  // (this rank's block)
  // Every rank's block: its values and checksum; this rank's block starts after the lower ranks'.
  const std::int64_t mine[2] = {static_cast<std::int64_t>(data.size()),
                                as_int64(fnv1a(data.data(), data.size_bytes()))};
  const std::vector<std::int64_t> all = comm::all_gather(mine);
  std::vector<std::int64_t> values, checksums;
  std::uint64_t first = 0, total = 0;
  for (int r = 0; r < comm::size(); ++r) {
    const auto n = static_cast<std::uint64_t>(all[2 * static_cast<std::size_t>(r)]);
    if (r < comm::rank()) first += n;
    total += n;
    values.push_back(all[2 * static_cast<std::size_t>(r)]);
    checksums.push_back(all[2 * static_cast<std::size_t>(r) + 1]);
  }
  try {
    h5::write_dataset_part(impl.arrays.get(), name, type, {total}, {first}, {data.size()}, data.data(),
                           impl.lcpl.get());
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("checkpoint '{}': {}", path, e.what()));
  }
  h5::Handle dset(H5Dopen2(impl.arrays.get(), name.c_str(), H5P_DEFAULT));
  h5::write_attribute(dset.get(), "block_values", values);
  h5::write_attribute(dset.get(), "block_checksums", checksums);
  if (!units.empty()) h5::write_attribute(dset.get(), "units", units);
}
}  // namespace

void CheckpointWriter::array(const std::string& name, std::span<const double> data, std::vector<std::uint64_t> shape,
                             const std::string& units) {
  write_array(*impl_, path_, name, H5T_NATIVE_DOUBLE, data, std::move(shape), units);
}
void CheckpointWriter::array(const std::string& name, std::span<const std::int64_t> data,
                             std::vector<std::uint64_t> shape, const std::string& units) {
  write_array(*impl_, path_, name, H5T_NATIVE_INT64, data, std::move(shape), units);
}
void CheckpointWriter::array(const std::string& name, std::span<const std::uint8_t> data,
                             std::vector<std::uint64_t> shape, const std::string& units) {
  write_array(*impl_, path_, name, H5T_NATIVE_UINT8, data, std::move(shape), units);
}
void CheckpointWriter::ranks_array(const std::string& name, std::span<const double> data, const std::string& units) {
  write_ranks_array(*impl_, path_, name, H5T_NATIVE_DOUBLE, data, units);
}
void CheckpointWriter::ranks_array(const std::string& name, std::span<const std::uint8_t> data,
                                   const std::string& units) {
  write_ranks_array(*impl_, path_, name, H5T_NATIVE_UINT8, data, units);
}

void CheckpointWriter::commit() {
  if (impl_->committed) return;
  auto close = [&] {
    impl_->arrays.reset();
    impl_->lcpl.reset();
    return impl_->file.reset();
  };
  if (impl_->every_rank) {
    // The ranks' arrays are in; rank 0 adds its attributes and arrays to the file alone.
    if (comm::any(!close())) {
      throw std::runtime_error(fmt::format("checkpoint '{}': closing the file failed (disk full?)", path_));
    }
    if (impl_->root) {
      impl_->file = h5::open_file_readwrite(impl_->tmp, true);
      impl_->arrays = h5::Handle(H5Gopen2(impl_->file.get(), "arrays", H5P_DEFAULT));
      impl_->lcpl = h5::Handle(H5Pcreate(H5P_LINK_CREATE));
      H5Pset_create_intermediate_group(impl_->lcpl.get(), 1);
      for (const auto& write : impl_->later) write(impl_->file.get(), impl_->arrays.get());
    }
  }
  if (impl_->root) {
    // The list of arrays, written last: a reader finds every listed dataset or reports which is
    // missing, without walking the file.
    h5::write_attribute(impl_->arrays.get(), "names", impl_->name_list);
    if (!close()) {
      throw std::runtime_error(fmt::format("checkpoint '{}': closing the file failed (disk full?)", path_));
    }
    fs::rename(impl_->tmp, path_);
  }
  if (impl_->every_rank) comm::barrier();
  impl_->committed = true;
}

// ---------------------------------------------------------------------------------------------
// Reader

std::vector<std::string> Checkpoint::names() const {
  std::vector<std::string> out;
  for (const auto& [name, a] : arrays_) out.push_back(name);
  return out;
}

const Checkpoint::Array& Checkpoint::get(const std::string& name) const {
  auto it = arrays_.find(name);
  if (it == arrays_.end()) {
    const std::string hint = closest_match(name, names());
    throw InputError(fmt::format("checkpoint '{}': no array '{}'{}", file_, name,
                                 hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint)));
  }
  return it->second;
}

const std::vector<std::uint64_t>& Checkpoint::shape(const std::string& name) const { return get(name).shape; }

namespace {
template <class T>
const std::vector<T>& typed(const Checkpoint::Array& a, const std::string& file, const std::string& name,
                            const char* type) {
  const auto* v = std::get_if<std::vector<T>>(&a.data);
  if (v == nullptr) throw InputError(fmt::format("checkpoint '{}': array '{}' is not of type {}", file, name, type));
  return *v;
}

template <class T>
void copy_out(const std::vector<T>& v, std::span<T> out, const std::string& file, const std::string& name) {
  if (v.size() != out.size()) {
    throw InputError(fmt::format("checkpoint '{}': array '{}' holds {} values, the run expects {}", file, name,
                                 v.size(), out.size()));
  }
  std::copy(v.begin(), v.end(), out.begin());
}
}  // namespace

const std::vector<double>& Checkpoint::doubles(const std::string& name) const {
  return typed<double>(get(name), file_, name, "double");
}
const std::vector<std::int64_t>& Checkpoint::int64s(const std::string& name) const {
  return typed<std::int64_t>(get(name), file_, name, "int64");
}
const std::vector<std::uint8_t>& Checkpoint::bytes(const std::string& name) const {
  return typed<std::uint8_t>(get(name), file_, name, "uint8");
}
void Checkpoint::read_into(const std::string& name, std::span<double> out) const {
  copy_out(doubles(name), out, file_, name);
}
void Checkpoint::read_into(const std::string& name, std::span<std::int64_t> out) const {
  copy_out(int64s(name), out, file_, name);
}
void Checkpoint::read_into(const std::string& name, std::span<std::uint8_t> out) const {
  copy_out(bytes(name), out, file_, name);
}

namespace {
template <class M>
const typename M::mapped_type& attr(const M& map, const std::string& file, const std::string& name, const char* kind) {
  auto it = map.find(name);
  if (it == map.end()) throw InputError(fmt::format("checkpoint '{}': no {} attribute '{}'", file, kind, name));
  return it->second;
}

struct AttrCollect {
  std::vector<std::string> names;
};
herr_t collect_attr(hid_t, const char* name, const H5A_info_t*, void* data) {
  static_cast<AttrCollect*>(data)->names.emplace_back(name);
  return 0;
}

/// Whether array `a` (read from `dset`) matches its stored checksum: one over the array, or one
/// per rank's block (an array the ranks wrote together). `fail(why)` makes the error for an
/// array without a usable checksum.
template <class Fail>
bool checksums_match(hid_t dset, const Checkpoint::Array& a, Fail fail) {
  std::int64_t stored = 0;
  std::vector<std::int64_t> values, checksums;
  const bool whole = h5::read_attribute(dset, "checksum", stored);
  if (!whole &&
      (!h5::read_attribute(dset, "block_values", values) || !h5::read_attribute(dset, "block_checksums", checksums)))
    throw fail("has no checksum");
  return std::visit(
      [&](const auto& v) {
        const std::size_t bytes = v.size() * sizeof(v[0]);
        if (whole)
          return stored == as_int64(fnv1a(v.data(), bytes)) ||
                 stored == as_int64(fnv1a(v.data(), bytes, kOlderOffsetBasis));
        if (values.size() != checksums.size()) throw fail("has block checksums that do not match its blocks");
        std::size_t at = 0;
        for (std::size_t k = 0; k < values.size(); ++k) {
          const auto n = static_cast<std::size_t>(values[k]);
          if (values[k] < 0 || n > v.size() - at) throw fail("has blocks that do not match its size");
          if (as_int64(fnv1a(v.data() + at, n * sizeof(v[0]))) != checksums[k]) return false;
          at += n;
        }
        if (at != v.size()) throw fail("has blocks that do not match its size");
        return true;
      },
      a.data);
}

template <class T>
Checkpoint::Array read_typed(hid_t dset, hid_t mem_type, std::vector<std::uint64_t> shape, std::uint64_t count,
                             bool& ok) {
  std::vector<T> v(count);
  ok = count == 0 || H5Dread(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0;
  return {std::move(shape), std::move(v)};
}
}  // namespace

double Checkpoint::real_attribute(const std::string& name) const { return attr(reals_, file_, name, "real"); }
std::int64_t Checkpoint::int_attribute(const std::string& name) const { return attr(ints_, file_, name, "integer"); }
const std::string& Checkpoint::text_attribute(const std::string& name) const {
  return attr(texts_, file_, name, "text");
}

Checkpoint read_checkpoint(const std::string& path) {
  auto fail = [&](const std::string& why) { return InputError(fmt::format("checkpoint '{}': {}", path, why)); };
  std::error_code ec;
  if (!fs::exists(path, ec)) throw fail("file does not exist");
  if (fs::is_directory(path, ec)) throw fail("is a folder, not a checkpoint file");
  if (!fs::is_regular_file(path, ec)) throw fail("not a regular file (a device or pipe cannot be a checkpoint)");
  h5::Handle file = h5::open_file_readonly(path);
  if (!file.valid()) {
    throw fail(fmt::format("not a readable HDF5 file (truncated or corrupt?): {}", h5::last_error()));
  }
  Checkpoint cp;
  cp.file_ = path;
  std::string format;
  if (!h5::read_attribute(file.get(), "format", format) || format != kFormat) {
    throw fail(fmt::format("not an oobleck checkpoint (format '{}', expected '{}')", format, kFormat));
  }
  if (!h5::read_attribute(file.get(), "step", cp.step_)) throw fail("attribute 'step' missing or unreadable");
  if (!h5::read_attribute(file.get(), "time", cp.time_)) throw fail("attribute 'time' missing or unreadable");
  if (!h5::read_attribute(file.get(), "config", cp.config_)) throw fail("attribute 'config' missing or unreadable");

  AttrCollect attrs;
  hsize_t idx = 0;
  if (H5Aiterate2(file.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect_attr, &attrs) < 0) {
    throw fail("cannot list attributes (corrupt?)");
  }
  for (const auto& a : attrs.names) {
    auto starts = [&](const char* p) { return a.rfind(p, 0) == 0; };
    bool ok = true;
    if (starts("real_")) {
      ok = h5::read_attribute(file.get(), a, cp.reals_[a.substr(5)]);
    } else if (starts("int_")) {
      ok = h5::read_attribute(file.get(), a, cp.ints_[a.substr(4)]);
    } else if (starts("text_")) {
      ok = h5::read_attribute(file.get(), a, cp.texts_[a.substr(5)]);
    }
    if (!ok) throw fail(fmt::format("attribute '{}' unreadable", a));
  }

  h5::Handle arrays(H5Gopen2(file.get(), "arrays", H5P_DEFAULT));
  std::string list;
  if (!arrays.valid() || !h5::read_attribute(arrays.get(), "names", list)) {
    throw fail("group '/arrays' or its list of names is missing (incomplete checkpoint)");
  }
  std::size_t pos = 0;
  while (pos < list.size()) {
    const std::size_t end = list.find('\n', pos);
    const std::string name = list.substr(pos, end - pos);
    pos = end == std::string::npos ? list.size() : end + 1;
    if (name.empty()) continue;
    h5::Handle dset(H5Dopen2(arrays.get(), name.c_str(), H5P_DEFAULT));
    if (!dset.valid()) throw fail(fmt::format("dataset '/arrays/{}' is missing", name));
    h5::Handle space(H5Dget_space(dset.get()));
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) throw fail(fmt::format("dataset '/arrays/{}': unreadable shape", name));
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    std::vector<std::uint64_t> shape(dims.begin(), dims.end());
    std::uint64_t count = 1;
    for (auto n : shape) count *= n;
    h5::Handle type(H5Dget_type(dset.get()));
    const H5T_class_t cls = H5Tget_class(type.get());
    const std::size_t size = H5Tget_size(type.get());
    bool ok = false;
    Checkpoint::Array a;
    if (cls == H5T_FLOAT && size == 8) {
      a = read_typed<double>(dset.get(), H5T_NATIVE_DOUBLE, shape, count, ok);
    } else if (cls == H5T_INTEGER && size == 8 && H5Tget_sign(type.get()) == H5T_SGN_2) {
      a = read_typed<std::int64_t>(dset.get(), H5T_NATIVE_INT64, shape, count, ok);
    } else if (cls == H5T_INTEGER && size == 1 && H5Tget_sign(type.get()) == H5T_SGN_NONE) {
      a = read_typed<std::uint8_t>(dset.get(), H5T_NATIVE_UINT8, shape, count, ok);
    } else {
      throw fail(fmt::format("dataset '/arrays/{}' has a type other than double, int64, uint8", name));
    }
    if (!ok) throw fail(fmt::format("dataset '/arrays/{}' cannot be read (truncated or corrupt?)", name));
    if (!checksums_match(dset.get(), a, [&](const std::string& why) {
          return fail(fmt::format("dataset '/arrays/{}' {}", name, why));
        }))
      throw fail(fmt::format("dataset '/arrays/{}' fails its checksum (corrupt data)", name));
    cp.arrays_.emplace(name, std::move(a));
  }
  return cp;
}

}  // namespace oobleck::io
