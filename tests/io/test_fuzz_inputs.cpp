// The fuzz targets' contract (tests/fuzz/targets.hpp) on every stored input: the hand-made edge
// cases of tests/fuzz/corpus, the inputs that once failed (tests/fuzz/regressions), and the
// repository's own scenes, presets and data files, each read without a crash or an exception
// other than InputError; the readers' answers to a few edge cases checked by name.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../fuzz/targets.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/csv.hpp"
#include "oobleck/scene/config.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = OOBLECK_SOURCE_DIR;

std::vector<fs::path> files_under(const fs::path& dir, const std::string& extension = "") {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && (extension.empty() || e.path().extension() == extension)) out.push_back(e.path());
  return out;
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Feed every file to the target; returns how many were fed.
template <class Target>
int replay(Target target, const std::vector<fs::path>& inputs) {
  for (const auto& p : inputs) {
    const std::string b = bytes_of(p);
    SCOPED_TRACE(p.string());
    EXPECT_EQ(target(reinterpret_cast<const std::uint8_t*>(b.data()), b.size()), 0);
  }
  return static_cast<int>(inputs.size());
}

std::vector<fs::path> stored(const std::string& target) {
  auto a = files_under(kRoot / "tests/fuzz/corpus" / target);
  const auto b = files_under(kRoot / "tests/fuzz/regressions" / target);
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

TEST(FuzzInputs, SceneReaderTakesEveryStoredInput) {
  auto inputs = stored("scene");
  for (const char* dir : {"scenes", "bench/scenes"}) {
    const auto s = files_under(kRoot / dir, ".toml");
    inputs.insert(inputs.end(), s.begin(), s.end());
  }
  EXPECT_GE(replay(oobleck::fuzz::scene, inputs), 20);
}

TEST(FuzzInputs, ParamsReaderTakesEveryStoredInput) {
  auto inputs = stored("params");
  const auto p = files_under(kRoot / "presets", ".toml");
  inputs.insert(inputs.end(), p.begin(), p.end());
  EXPECT_GE(replay(oobleck::fuzz::params, inputs), 10);
}

TEST(FuzzInputs, CsvReaderTakesEveryStoredInput) {
  auto inputs = stored("csv");
  const auto d = files_under(kRoot / "docs/fitting", ".csv");
  inputs.insert(inputs.end(), d.begin(), d.end());
  const auto e = files_under(kRoot / "tests/rheology/data/rheometer");  // instrument exports
  inputs.insert(inputs.end(), e.begin(), e.end());
  EXPECT_GE(replay(oobleck::fuzz::csv, inputs), 14);
}

TEST(FuzzInputs, CheckpointReaderTakesEveryStoredInput) {
  EXPECT_GE(replay(oobleck::fuzz::checkpoint, stored("checkpoint")), 2);
}

TEST(FuzzInputs, DeviceFilesAreRefusedNotRead) {
  // A scene naming /dev/zero as its parameter file would otherwise read forever.
  const std::string scene = (kRoot / "scenes/verification/settling.toml").string();
  auto message = [](const auto& load) {
    try {
      load();
    } catch (const oobleck::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string preset = message([&] { (void)oobleck::scene::load_scene(scene, {"material.preset=/dev/zero"}); });
  EXPECT_NE(preset.find("unknown preset '/dev/zero'"), std::string::npos) << preset;
  std::string text = bytes_of(scene);
  const auto at = text.find("preset = \"hermes2016\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("preset = \"hermes2016\"").size(), "params = \"/dev/zero\"");
  const std::string copy =
      oobleck::fuzz::as_file(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), ".device_params.toml");
  const std::string params = message([&] { (void)oobleck::scene::load_scene(copy); });
  EXPECT_NE(params.find("/dev/zero: not a regular file"), std::string::npos) << params;
  const std::string csv = message([] { (void)oobleck::io::read_csv("/dev/zero"); });
  EXPECT_NE(csv.find("/dev/zero: not a regular file"), std::string::npos) << csv;
}
