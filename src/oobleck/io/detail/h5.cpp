#include "oobleck/io/detail/h5.hpp"

#include <atomic>
#include <stdexcept>

#include <fmt/format.h>
// Parallel HDF5 (files that every rank writes) in a build with MPI: CMakeLists.txt links Debian's
// libhdf5-openmpi then.
#if defined(OOBLECK_HAVE_MPI) && defined(H5_HAVE_PARALLEL)
#define OOBLECK_PARALLEL_HDF5 1
#include <mpi.h>  // (MPI_COMM_WORLD for parallel HDF5's file access; core/comm.cpp does the rest)
#endif

#include "oobleck/io/hdf5_state.hpp"

namespace oobleck::io::h5 {

namespace {
std::atomic<bool> g_file_close_failed{false};
}  // namespace

bool Handle::reset() {
  if (id_ < 0) return true;
  herr_t status = 0;
  switch (H5Iget_type(id_)) {
    case H5I_FILE:
      status = H5Fclose(id_);
      if (status < 0) g_file_close_failed = true;
      break;
    case H5I_GROUP: status = H5Gclose(id_); break;
    case H5I_DATASET: status = H5Dclose(id_); break;
    case H5I_DATASPACE: status = H5Sclose(id_); break;
    case H5I_DATATYPE: status = H5Tclose(id_); break;
    case H5I_ATTR: status = H5Aclose(id_); break;
    case H5I_GENPROP_LST: status = H5Pclose(id_); break;
    default: status = H5Idec_ref(id_); break;
  }
  id_ = H5I_INVALID_HID;
  return status >= 0;
}

void silence_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

namespace {
herr_t keep_innermost(unsigned n, const H5E_error2_t* err, void* data) {
  auto* out = static_cast<std::string*>(data);
  if (n == 0 && err != nullptr && err->desc != nullptr) *out = err->desc;
  return 0;
}

std::string failure(const std::string& what) {
  const std::string reason = last_error();
  return reason.empty() ? what : fmt::format("{} ({})", what, reason);
}

Handle scalar_space() { return Handle(H5Screate(H5S_SCALAR)); }

Handle simple_space(const std::vector<std::uint64_t>& shape) {
  std::vector<hsize_t> dims(shape.begin(), shape.end());
  return Handle(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
}

void write_attribute_raw(hid_t loc, const std::string& name, hid_t type, hid_t space, const void* data) {
  if (H5Aexists(loc, name.c_str()) > 0) H5Adelete(loc, name.c_str());
  Handle attr(H5Acreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT));
  if (!attr.valid() || H5Awrite(attr.get(), type, data) < 0) {
    throw std::runtime_error(failure(fmt::format("cannot write attribute '{}'", name)));
  }
}

template <class T>
bool read_number_attribute(hid_t loc, const std::string& name, hid_t mem_type, T& value) {
  if (!has_attribute(loc, name)) return false;
  Handle attr(H5Aopen(loc, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) return false;
  Handle space(H5Aget_space(attr.get()));
  if (H5Sget_simple_extent_npoints(space.get()) != 1) return false;
  Handle type(H5Aget_type(attr.get()));
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER) return false;
  return H5Aread(attr.get(), mem_type, &value) >= 0;
}
}  // namespace

std::string last_error() {
  std::string out;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_innermost, &out);
  H5Eclear2(H5E_DEFAULT);
  return out;
}

Handle create_file(const std::string& path, bool large_attributes, bool every_rank) {
  silence_errors();
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (large_attributes) H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST);
  if (every_rank) {
#ifdef OOBLECK_PARALLEL_HDF5
    H5Pset_fapl_mpio(fapl.get(), MPI_COMM_WORLD, MPI_INFO_NULL);
#else
    throw std::logic_error(fmt::format("'{}': a file of every rank needs a build with MPI", path));
#endif
  }
  Handle f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()));
  if (!f.valid()) throw std::runtime_error(failure(fmt::format("cannot create HDF5 file '{}'", path)));
  return f;
}

Handle open_file_readonly(const std::string& path) {
  silence_errors();
  return Handle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
}

Handle open_file_readwrite(const std::string& path, bool large_attributes) {
  silence_errors();
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (large_attributes) H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST);
  Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl.get()));
  if (!f.valid()) throw std::runtime_error(failure(fmt::format("cannot open HDF5 file '{}' for writing", path)));
  return f;
}

bool written_by_every_rank([[maybe_unused]] hid_t loc) {
#ifdef OOBLECK_PARALLEL_HDF5
  Handle file(H5Iget_file_id(loc));
  Handle fapl(H5Fget_access_plist(file.get()));
  return H5Pget_driver(fapl.get()) == H5FD_MPIO;
#else
  return false;
#endif
}

Handle create_group(hid_t loc, const std::string& name) {
  Handle g(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.valid()) throw std::runtime_error(failure(fmt::format("cannot create HDF5 group '{}'", name)));
  return g;
}

void write_dataset_part(hid_t loc, const std::string& name, hid_t type, const std::vector<std::uint64_t>& shape,
                        const std::vector<std::uint64_t>& start, const std::vector<std::uint64_t>& count,
                        const void* data, hid_t link_properties) {
  Handle file_space = simple_space(shape);
  Handle dset(H5Dcreate2(loc, name.c_str(), type, file_space.get(), link_properties, H5P_DEFAULT, H5P_DEFAULT));
  if (!dset.valid()) throw std::runtime_error(failure(fmt::format("cannot create dataset '{}'", name)));
  std::uint64_t n = 1;
  for (auto c : count) n *= c;
  const bool collective = written_by_every_rank(loc);
  if (n == 0 && !collective) return;
  Handle memory_space;
  if (n > 0) {
    const std::vector<hsize_t> at(start.begin(), start.end()), extent(count.begin(), count.end());
    H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, at.data(), nullptr, extent.data(), nullptr);
    memory_space = simple_space(count);
  } else {  // (a rank without values still takes part in the collective write)
    H5Sselect_none(file_space.get());
    memory_space = Handle(H5Scopy(file_space.get()));
  }
  Handle transfer(H5Pcreate(H5P_DATASET_XFER));
#ifdef OOBLECK_PARALLEL_HDF5
  if (collective) H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE);
#endif
  const double none = 0.0;
  if (H5Dwrite(dset.get(), type, memory_space.get(), file_space.get(), transfer.get(), n > 0 ? data : &none) < 0) {
    throw std::runtime_error(failure(fmt::format("cannot write dataset '{}'", name)));
  }
}

void write_attribute(hid_t loc, const std::string& name, double value) {
  Handle space = scalar_space();
  write_attribute_raw(loc, name, H5T_NATIVE_DOUBLE, space.get(), &value);
}

void write_attribute(hid_t loc, const std::string& name, std::int64_t value) {
  Handle space = scalar_space();
  write_attribute_raw(loc, name, H5T_NATIVE_INT64, space.get(), &value);
}

void write_attribute(hid_t loc, const std::string& name, const std::string& value) {
  // Fixed-length string of exactly the value's size (at least 1 byte: HDF5 refuses size 0).
  Handle type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.get(), value.empty() ? 1 : value.size());
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  Handle space = scalar_space();
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  write_attribute_raw(loc, name, type.get(), space.get(), padded.data());
}

void write_attribute(hid_t loc, const std::string& name, const std::vector<double>& values) {
  Handle space = simple_space({values.size()});
  write_attribute_raw(loc, name, H5T_NATIVE_DOUBLE, space.get(), values.data());
}

void write_attribute(hid_t loc, const std::string& name, const std::vector<std::int64_t>& values) {
  Handle space = simple_space({values.size()});
  write_attribute_raw(loc, name, H5T_NATIVE_INT64, space.get(), values.data());
}

bool has_attribute(hid_t loc, const std::string& name) { return H5Aexists(loc, name.c_str()) > 0; }

bool read_attribute(hid_t loc, const std::string& name, double& value) {
  return read_number_attribute(loc, name, H5T_NATIVE_DOUBLE, value);
}

bool read_attribute(hid_t loc, const std::string& name, std::int64_t& value) {
  return read_number_attribute(loc, name, H5T_NATIVE_INT64, value);
}

bool read_attribute(hid_t loc, const std::string& name, std::string& value) {
  if (!has_attribute(loc, name)) return false;
  Handle attr(H5Aopen(loc, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) return false;
  Handle type(H5Aget_type(attr.get()));
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) > 0) return false;
  const std::size_t size = H5Tget_size(type.get());
  std::string buf(size, '\0');
  // Read with the stored type itself (same size, padding and character set: no conversion).
  if (H5Aread(attr.get(), type.get(), buf.data()) < 0) return false;
  const auto end = buf.find('\0');
  value = end == std::string::npos ? buf : buf.substr(0, end);
  return true;
}

bool read_attribute(hid_t loc, const std::string& name, std::vector<std::int64_t>& values) {
  if (!has_attribute(loc, name)) return false;
  Handle attr(H5Aopen(loc, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) return false;
  Handle space(H5Aget_space(attr.get()));
  Handle type(H5Aget_type(attr.get()));
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0 || H5Tget_class(type.get()) != H5T_INTEGER) return false;
  values.assign(static_cast<std::size_t>(n), 0);
  return n == 0 || H5Aread(attr.get(), H5T_NATIVE_INT64, values.data()) >= 0;
}

}  // namespace oobleck::io::h5

namespace oobleck::io {
bool hdf5_file_close_failed() { return h5::g_file_close_failed.load(); }
}  // namespace oobleck::io
