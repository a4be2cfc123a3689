#pragma once
// The fuzz targets' bodies (docs/reliability.md "Fuzzing"): each takes arbitrary bytes as the
// content of one input file, hands it to the reader a user's file goes through, and accepts
// exactly two outcomes: the reader's result, or an InputError (a message naming the file and the
// rule). Anything else — a crash, a sanitizer report, another exception, a hang — is a bug.
// Built into libFuzzer executables (tests/fuzz/fuzz_<target>.cpp, preset `fuzz`) and into the
// test suite, which replays every stored input (tests/io/test_fuzz_inputs.cpp).
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/io/csv.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/rheology/params.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::fuzz {

/// The bytes as a file of this process (the readers take paths, as from the command line).
inline std::string as_file(const std::uint8_t* data, std::size_t size, const char* suffix) {
  std::string path = "/tmp/oobleck_fuzz_" + std::to_string(::getpid()) + suffix;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// A scene file (TOML → validated SceneConfig). A line "#--set" splits the input: the lines after
/// it are `--set` overrides.
inline int scene(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> sets;
  if (const auto cut = text.find("\n#--set\n"); cut != std::string_view::npos) {
    std::string_view rest = text.substr(cut + 8);
    text = text.substr(0, cut + 1);
    while (!rest.empty()) {
      const auto end = rest.find('\n');
      sets.emplace_back(rest.substr(0, end));
      rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end + 1);
    }
  }
  const std::string path = as_file(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), ".toml");
  try {
    (void)scene::load_scene(path, sets);
  } catch (const InputError&) {
  }
  return 0;
}

/// A parameter file (`--params FILE`, [material] params = FILE).
inline int params(const std::uint8_t* data, std::size_t size) {
  const std::string path = as_file(data, size, ".params.toml");
  try {
    (void)rheology::load_params_file(path);
  } catch (const InputError&) {
  }
  return 0;
}

/// A data file (`oobleck rheology fit --data`, `rheology import`): oobleck's CSV table and every
/// column it names; the same bytes as an instrument export (io/rheometer.hpp): its table, its
/// flow-curve rows and the first step selected by name.
inline int csv(const std::uint8_t* data, std::size_t size) {
  const std::string path = as_file(data, size, ".csv");
  try {
    const io::CsvTable t = io::read_csv(path);
    for (const auto& name : t.header) (void)t.column(name);
  } catch (const InputError&) {
  }
  try {
    const io::RheometerFile f = io::read_rheometer(path);
    (void)io::to_table(f);
    if (!f.steps.empty()) (void)io::select_steps(f, f.steps.front().name);
    (void)io::flow_curve_rows(f, "");
  } catch (const InputError&) {
  }
  return 0;
}

/// A checkpoint (`oobleck run --restart`): the file, and every array it lists.
inline int checkpoint(const std::uint8_t* data, std::size_t size) {
  const std::string path = as_file(data, size, ".h5");
  try {
    const io::Checkpoint cp = io::read_checkpoint(path);
    for (const auto& name : cp.names()) {
      (void)cp.shape(name);
      try {
        (void)cp.doubles(name);
      } catch (const InputError&) {  // another type: its reader names it
      }
    }
    (void)cp.config();
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace oobleck::fuzz
