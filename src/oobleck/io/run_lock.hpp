#pragma once
// An exclusive lock on a run folder: `oobleck run` holds it from before its first write to its
// end, so a second run into the same folder (or a --restart of a run that is still going) is
// refused instead of interleaving files. The lock is flock(2) on DIR/.oobleck.lock, which holds
// the owner's pid; the kernel releases it when the process ends, however it ends (no stale locks).
#include <string>

namespace oobleck::io {

class RunFolderLock {
 public:
  /// Lock `dir` (which exists). InputError when another process holds it (naming its pid) or
  /// the lock file cannot be opened.
  explicit RunFolderLock(const std::string& dir);
  ~RunFolderLock();
  RunFolderLock(const RunFolderLock&) = delete;
  RunFolderLock& operator=(const RunFolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace oobleck::io
