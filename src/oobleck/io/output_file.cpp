#include "oobleck/io/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <unistd.h>

#include "oobleck/core/error.hpp"

namespace oobleck::io {
namespace fs = std::filesystem;

void check_writable(const std::string& path, const std::string& option) {
  if (path.empty()) throw InputError(fmt::format("{}: empty output path", option));
  const fs::path p(path);
  fs::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError(
        fmt::format("{} '{}': cannot write output: folder '{}' does not exist", option, path, dir.string()));
  }
  if (fs::is_directory(p, ec)) {
    throw InputError(fmt::format("{} '{}': cannot write output: it is a folder", option, path));
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw InputError(fmt::format("{} '{}': cannot write output: folder '{}' is not writable ({})", option, path,
                                 dir.string(), std::strerror(errno)));
  }
  if (fs::exists(p, ec) && ::access(p.c_str(), W_OK) != 0) {
    throw InputError(fmt::format("{} '{}': cannot write output: file is not writable", option, path));
  }
}

OutputFile::OutputFile(std::string path, std::string option) : path_(std::move(path)) {
  check_writable(path_, option);
  tmp_ = fmt::format("{}.tmp-{}", path_, ::getpid());
  out_.open(tmp_, std::ios::out | std::ios::trunc);
  if (!out_) throw InputError(fmt::format("{} '{}': cannot open for writing", option, path_));
}

OutputFile::~OutputFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void OutputFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw NumericalError(fmt::format("writing '{}' failed (disk full?)", path_));
  fs::rename(tmp_, path_);
  committed_ = true;
}

void write_file_atomically(const std::string& path, const std::string& content, const std::string& option) {
  OutputFile f(path, option);
  f.stream() << content;
  f.commit();
}

}  // namespace oobleck::io
