// Checkpoints: bit-exact round trip, atomic writing, clear InputError for missing, foreign,
// truncated, corrupt files and missing datasets.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>
#include <hdf5.h>

#include "io_test_util.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"

namespace fs = std::filesystem;
using namespace oobleck;
using namespace oobleck::io;
using oobleck::test::read_text;
using oobleck::test::TempDir;

namespace {

std::vector<double> awkward_doubles() {
  double payload_nan;
  const std::uint64_t bits = 0x7ff8dead0000beefULL;  // quiet NaN with a payload
  std::memcpy(&payload_nan, &bits, sizeof bits);
  return {0.0,
          -0.0,
          1.0 / 3.0,
          -2.5e-310,  // subnormal
          std::numeric_limits<double>::max(),
          std::numeric_limits<double>::lowest(),
          std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(),
          payload_nan,
          std::nextafter(1.0, 2.0),
          6.02214076e23,
          -1e-300};
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

/// A small valid checkpoint with one distinctive double array; returns its path.
std::string write_small(const TempDir& dir, const std::string& name = "cp.h5") {
  std::string path = dir.file(name);
  std::vector<double> marker(64);
  for (std::size_t i = 0; i < marker.size(); ++i) marker[i] = 1234.5678 + static_cast<double>(i);
  std::vector<std::int64_t> ids{1, 2, 3};
  CheckpointWriter w(path);
  w.set_step(42);
  w.set_time(0.125);
  w.set_config("[run]\nsteps = 100\n");
  w.array("grains/x", marker);
  w.array("grains/id", ids);
  w.commit();
  return path;
}

}  // namespace

TEST(Checkpoint, RoundTripIsBitExact) {
  TempDir dir;
  const std::string path = dir.file("checkpoint.h5");
  const auto d = awkward_doubles();
  const std::vector<std::int64_t> ints{
      0, -1, std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max(), 42, -7};
  std::vector<std::uint8_t> bytes(256);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i);
  std::vector<double> matrix(12);
  for (std::size_t i = 0; i < matrix.size(); ++i) matrix[i] = std::sin(static_cast<double>(i) + 0.1);
  std::string config;
  for (int i = 0; config.size() < 200000; ++i)
    config += "[material.grains]  # \xcf\x86 = 0.47, line " + std::to_string(i) + "\n";
  const double time = 1.0 / 7.0;

  {
    CheckpointWriter w(path);
    w.set_step(123456789012LL);
    w.set_time(time);
    w.set_config(config);
    w.attribute("dt", 1e-6 / 3.0);
    w.attribute("rng_state", std::int64_t{-99});
    w.attribute("engine", std::string("apic"));
    w.array("grains/velocity", matrix, {4, 3});
    w.array("special", d);
    w.array("grains/id", ints, {2, 3});
    w.array("flags", bytes);
    w.array("empty", std::span<const double>{});
    w.commit();
  }
  EXPECT_TRUE(fs::exists(path));
  for (const auto& e : fs::directory_iterator(dir.str())) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }

  const Checkpoint cp = read_checkpoint(path);
  EXPECT_EQ(cp.file(), path);
  EXPECT_EQ(cp.step(), 123456789012LL);
  const double time_back = cp.time();
  EXPECT_EQ(std::bit_cast<std::uint64_t>(time), std::bit_cast<std::uint64_t>(time_back));  // bit for bit
  EXPECT_EQ(cp.config(), config);
  const double dt = 1e-6 / 3.0;
  EXPECT_EQ(cp.real_attribute("dt"), dt);
  EXPECT_EQ(cp.int_attribute("rng_state"), -99);
  EXPECT_EQ(cp.text_attribute("engine"), "apic");
  EXPECT_EQ(cp.names(), (std::vector<std::string>{"empty", "flags", "grains/id", "grains/velocity", "special"}));
  EXPECT_TRUE(same_bits(cp.doubles("special"), d));
  EXPECT_TRUE(std::signbit(cp.doubles("special")[1]));
  EXPECT_TRUE(same_bits(cp.doubles("grains/velocity"), matrix));
  EXPECT_EQ(cp.shape("grains/velocity"), (std::vector<std::uint64_t>{4, 3}));
  EXPECT_EQ(cp.int64s("grains/id"), ints);
  EXPECT_EQ(cp.shape("grains/id"), (std::vector<std::uint64_t>{2, 3}));
  EXPECT_EQ(cp.bytes("flags"), bytes);
  EXPECT_TRUE(cp.doubles("empty").empty());
  EXPECT_EQ(cp.shape("empty"), (std::vector<std::uint64_t>{0}));

  std::vector<double> into(12);
  cp.read_into("grains/velocity", into);
  EXPECT_TRUE(same_bits(into, matrix));

  // Raw check through the HDF5 C API: the file is plain HDF5 other tools can read.
  const auto raw = oobleck::test::read_h5_doubles(path, "/arrays/grains/velocity");
  ASSERT_TRUE(raw.ok);
  EXPECT_TRUE(same_bits(raw.values, matrix));
}

TEST(Checkpoint, AccessErrorsNameFileAndArray) {
  TempDir dir;
  const std::string path = write_small(dir);
  const Checkpoint cp = read_checkpoint(path);
  const std::string missing = message_of([&] { (void)cp.doubles("grains/xx"); });
  EXPECT_NE(missing.find(path), std::string::npos) << missing;
  EXPECT_NE(missing.find("no array 'grains/xx'"), std::string::npos) << missing;
  EXPECT_NE(missing.find("did you mean 'grains/x'"), std::string::npos) << missing;
  EXPECT_NE(message_of([&] { (void)cp.int64s("grains/x"); }).find("not of type int64"), std::string::npos);
  std::vector<double> wrong(3);
  EXPECT_NE(message_of([&] { cp.read_into("grains/x", wrong); }).find("holds 64 values, the run expects 3"),
            std::string::npos);
  EXPECT_THROW((void)cp.real_attribute("nothing"), InputError);
}

TEST(Checkpoint, MissingFileIsInputError) {
  TempDir dir;
  const std::string path = dir.file("nope.h5");
  const std::string msg = message_of([&] { (void)read_checkpoint(path); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
  EXPECT_NE(message_of([&] { (void)read_checkpoint(dir.str()); }).find("folder"), std::string::npos);
}

TEST(Checkpoint, NonHdf5FileIsInputError) {
  TempDir dir;
  std::ofstream(dir.file("text.h5")) << "step = 3\n";
  const std::string msg = message_of([&] { (void)read_checkpoint(dir.file("text.h5")); });
  EXPECT_NE(msg.find("not a readable HDF5 file"), std::string::npos) << msg;
}

TEST(Checkpoint, ForeignHdf5FileIsInputError) {
  TempDir dir;
  const std::string path = dir.file("other.h5");
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  H5Fclose(f);
  const std::string msg = message_of([&] { (void)read_checkpoint(path); });
  EXPECT_NE(msg.find("not an oobleck checkpoint"), std::string::npos) << msg;
}

TEST(Checkpoint, TruncatedFileIsInputError) {
  TempDir dir;
  const std::string path = write_small(dir);
  const auto size = fs::file_size(path);
  fs::resize_file(path, size / 2);
  const std::string msg = message_of([&] { (void)read_checkpoint(path); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("(no InputError)"), 0u) << msg;
}

TEST(Checkpoint, CorruptDataFailsChecksum) {
  TempDir dir;
  const std::string path = write_small(dir);
  std::string bytes = read_text(path);
  const double target = 1234.5678 + 10.0;
  char pattern[sizeof(double)];
  std::memcpy(pattern, &target, sizeof target);
  const auto at = bytes.find(std::string(pattern, sizeof pattern));
  ASSERT_NE(at, std::string::npos);
  bytes[at] = static_cast<char>(bytes[at] ^ 0x01);  // one flipped bit in the raw data
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  const std::string msg = message_of([&] { (void)read_checkpoint(path); });
  EXPECT_NE(msg.find("'/arrays/grains/x' fails its checksum"), std::string::npos) << msg;
}

namespace {
/// FNV-1a 64 (the published algorithm: offset basis 14695981039346656037, prime 1099511628211).
std::int64_t fnv1a_64(const void* data, std::size_t bytes) {
  std::uint64_t h = 14695981039346656037ULL;
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= static_cast<const unsigned char*>(data)[i];
    h *= 1099511628211ULL;
  }
  return std::bit_cast<std::int64_t>(h);
}

/// Replace array `name`'s whole-array checksum with per-block ones (what the ranks of a
/// decomposed run write): `values` per block, and their checksums.
void use_block_checksums(const std::string& path, const std::string& name, const std::vector<std::int64_t>& values,
                         const std::vector<std::int64_t>& checksums) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t dset = H5Dopen2(file, ("arrays/" + name).c_str(), H5P_DEFAULT);
  H5Adelete(dset, "checksum");
  for (const auto& [attr, v] : {std::pair{"block_values", &values}, std::pair{"block_checksums", &checksums}}) {
    const hsize_t n = v->size();
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t a = H5Acreate2(dset, attr, H5T_NATIVE_INT64, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT64, v->data());
    H5Aclose(a);
    H5Sclose(space);
  }
  H5Dclose(dset);
  H5Fclose(file);
}
}  // namespace

// The whole-array checksum is FNV-1a 64 of the raw bytes; a checkpoint whose checksums were
// made with the offset basis 1469598103934665603 (older oobleck versions) still reads.
TEST(Checkpoint, ChecksumIsFnv1a64AndTheOlderBasisReads) {
  TempDir dir;
  std::vector<double> marker(64);
  for (std::size_t i = 0; i < marker.size(); ++i) marker[i] = 1234.5678 + static_cast<double>(i);
  const std::string path = write_small(dir);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t dset = H5Dopen2(file, "arrays/grains/x", H5P_DEFAULT);
  const hid_t attr = H5Aopen(dset, "checksum", H5P_DEFAULT);
  std::int64_t stored = 0;
  H5Aread(attr, H5T_NATIVE_INT64, &stored);
  EXPECT_EQ(stored, fnv1a_64(marker.data(), marker.size() * sizeof(double)));
  std::uint64_t older = 1469598103934665603ULL;
  for (std::size_t i = 0; i < marker.size() * sizeof(double); ++i) {
    older ^= reinterpret_cast<const unsigned char*>(marker.data())[i];
    older *= 1099511628211ULL;
  }
  H5Awrite(attr, H5T_NATIVE_INT64, &older);
  H5Aclose(attr);
  H5Dclose(dset);
  H5Fclose(file);
  EXPECT_TRUE(same_bits(read_checkpoint(path).doubles("grains/x"), marker));
}

// An array that the ranks wrote together is checked block by block: the right checksums read
// back, one wrong block fails, and blocks that do not add up to the array are refused.
TEST(Checkpoint, BlockChecksumsAreCheckedBlockByBlock) {
  TempDir dir;
  std::vector<double> marker(64);
  for (std::size_t i = 0; i < marker.size(); ++i) marker[i] = 1234.5678 + static_cast<double>(i);
  const auto sum = [&](std::size_t from, std::size_t n) { return fnv1a_64(marker.data() + from, n * sizeof(double)); };

  const std::string good = write_small(dir, "good.h5");
  use_block_checksums(good, "grains/x", {20, 0, 44}, {sum(0, 20), sum(20, 0), sum(20, 44)});
  const Checkpoint cp = read_checkpoint(good);
  EXPECT_TRUE(same_bits(cp.doubles("grains/x"), marker));

  const std::string wrong = write_small(dir, "wrong.h5");
  use_block_checksums(wrong, "grains/x", {20, 44}, {sum(0, 20), sum(21, 43)});
  std::string msg = message_of([&] { (void)read_checkpoint(wrong); });
  EXPECT_NE(msg.find("'/arrays/grains/x' fails its checksum"), std::string::npos) << msg;

  const std::string short_blocks = write_small(dir, "short.h5");
  use_block_checksums(short_blocks, "grains/x", {20, 40}, {sum(0, 20), sum(20, 40)});
  msg = message_of([&] { (void)read_checkpoint(short_blocks); });
  EXPECT_NE(msg.find("'/arrays/grains/x' has blocks that do not match its size"), std::string::npos) << msg;

  const std::string unpaired = write_small(dir, "unpaired.h5");
  use_block_checksums(unpaired, "grains/x", {64}, {});
  msg = message_of([&] { (void)read_checkpoint(unpaired); });
  EXPECT_NE(msg.find("block checksums that do not match its blocks"), std::string::npos) << msg;
}

TEST(Checkpoint, MissingDatasetIsInputError) {
  TempDir dir;
  const std::string path = write_small(dir);
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/arrays/grains/id", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  const std::string msg = message_of([&] { (void)read_checkpoint(path); });
  EXPECT_NE(msg.find("dataset '/arrays/grains/id' is missing"), std::string::npos) << msg;
}

TEST(Checkpoint, UncommittedWriterLeavesEarlierCheckpointIntact) {
  TempDir dir;
  const std::string path = write_small(dir);
  const std::string before = read_text(path);
  {
    CheckpointWriter w(path);
    w.set_step(999);
    std::vector<double> v{1, 2, 3};
    w.array("grains/x", v);
    // destroyed without commit(), as when the run throws mid-checkpoint
  }
  EXPECT_EQ(read_text(path), before);
  EXPECT_EQ(read_checkpoint(path).step(), 42);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.str())) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(Checkpoint, WriterRefusesBadInput) {
  TempDir dir;
  EXPECT_THROW(CheckpointWriter(dir.file("missing/cp.h5")), InputError);
  CheckpointWriter w(dir.file("cp.h5"));
  std::vector<double> v{1, 2, 3, 4};
  EXPECT_THROW(w.array("a", v, {3}), std::invalid_argument);
  EXPECT_THROW(w.array("/abs", v), std::invalid_argument);
  EXPECT_THROW(w.array("sp ace", v), std::invalid_argument);
  w.array("a", v, {2, 2});
  EXPECT_THROW(w.array("a", v), std::invalid_argument);
  EXPECT_THROW(w.attribute("bad/name", 1.0), std::invalid_argument);
}
