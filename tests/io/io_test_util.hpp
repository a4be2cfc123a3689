#pragma once
// Helpers for the io tests: a private temporary folder per test and HDF5 reading.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

namespace oobleck::test {

/// A fresh folder under the system temporary directory, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("oobleck_io_" + std::string(info->test_suite_name()) + "_" +
                                                      info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string str() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

template <class T>
struct H5Data {
  std::vector<std::uint64_t> shape;
  std::vector<T> values;
  bool ok = false;
};

/// Read dataset `name` of `file` with the plain HDF5 C API (memory type `mem`).
template <class T>
H5Data<T> read_h5(const std::string& file, const std::string& name, hid_t mem) {
  H5Data<T> out;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  if (d >= 0) {
    const hid_t s = H5Dget_space(d);
    const int rank = H5Sget_simple_extent_ndims(s);
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
    H5Sget_simple_extent_dims(s, dims.data(), nullptr);
    out.shape.assign(dims.begin(), dims.end());
    std::uint64_t n = 1;
    for (auto v : dims) n *= v;
    out.values.resize(n);
    out.ok = n == 0 || H5Dread(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.values.data()) >= 0;
    H5Sclose(s);
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

inline H5Data<double> read_h5_doubles(const std::string& file, const std::string& name) {
  return read_h5<double>(file, name, H5T_NATIVE_DOUBLE);
}

/// A double attribute of the object at `object` ("/" for the file).
inline bool read_h5_attr(const std::string& file, const std::string& object, const std::string& attr, double& v) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  const hid_t a = H5Aopen_by_name(f, object.c_str(), attr.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  const bool ok = a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &v) >= 0;
  if (a >= 0) H5Aclose(a);
  H5Fclose(f);
  return ok;
}

/// A string attribute of the object at `object` ("/" for the file, "/bodies/grains/mass" for a
/// dataset); false when absent or not a string.
inline bool read_h5_text_attr(const std::string& file, const std::string& object, const std::string& attr,
                              std::string& v) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  bool ok = false;
  const hid_t a = H5Aopen_by_name(f, object.c_str(), attr.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  if (a >= 0) {
    const hid_t t = H5Aget_type(a);
    if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) <= 0) {
      std::string buf(H5Tget_size(t), '\0');
      ok = H5Aread(a, t, buf.data()) >= 0;
      v = buf.substr(0, buf.find('\0'));
    }
    H5Tclose(t);
    H5Aclose(a);
  }
  H5Fclose(f);
  return ok;
}

/// The paths of every dataset in `file` ("/bodies/grains/mass", ...).
inline std::vector<std::string> h5_datasets(const std::string& file) {
  std::vector<std::string> out;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  H5Lvisit(
      f, H5_INDEX_NAME, H5_ITER_NATIVE,
      [](hid_t group, const char* name, const H5L_info_t*, void* data) -> herr_t {
        const hid_t o = H5Oopen(group, name, H5P_DEFAULT);
        if (o >= 0 && H5Iget_type(o) == H5I_DATASET) {
          std::string path(1, '/');
          path.append(name);
          static_cast<std::vector<std::string>*>(data)->push_back(std::move(path));
        }
        if (o >= 0) H5Oclose(o);
        return 0;
      },
      &out);
  H5Fclose(f);
  return out;
}

}  // namespace oobleck::test
