#include "oobleck/io/run_lock.hpp"

#include <cerrno>
#include <cstring>
#include <string>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::io {

RunFolderLock::RunFolderLock(const std::string& dir) {
  const std::string path = dir + "/.oobleck.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(fmt::format("{}: cannot open the run folder's lock: {}", path, std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char buf[32] = {};
    const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK) {
      const std::string pid = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("unknown");
      throw InputError(fmt::format(
          "{}: another oobleck run (pid {}) is writing into this folder; wait for it to end or choose another --out",
          dir, pid));
    }
    throw InputError(fmt::format("{}: cannot lock the run folder: {}", path, std::strerror(err)));
  }
  const std::string pid = std::to_string(::getpid());
  // The pid only serves the message of a refused second run ("unknown" without it).
  [[maybe_unused]] const bool noted =
      ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) == static_cast<ssize_t>(pid.size());
}

RunFolderLock::~RunFolderLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

}  // namespace oobleck::io
