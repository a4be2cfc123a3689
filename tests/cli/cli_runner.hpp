#pragma once
// Run the oobleck CLI from tests: exit status, captured stdout+stderr, and a fresh temp folder.
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <sys/wait.h>

namespace clitest {

struct Result {
  int status = -1;
  std::string output;
};

/// Run a shell command: exit status and captured stdout+stderr.
inline Result shell(const std::string& command) {
  Result r;
  const std::string cmd = command + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int rc = ::pclose(pipe);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

/// Run `oobleck ARGS`; with a launcher, `LAUNCHER oobleck ARGS` (e.g. the dynamic loader).
inline Result run(const std::string& args, const std::string& launcher = "") {
  return shell((launcher.empty() ? "" : launcher + " ") + std::string(OOBLECK_CLI) + " " + args);
}

/// A fresh, empty folder removed at the end of the test.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    path = std::filesystem::temp_directory_path() /
           ("oobleck_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  static int& counter() {
    static int c = 0;
    return c;
  }
};

}  // namespace clitest
