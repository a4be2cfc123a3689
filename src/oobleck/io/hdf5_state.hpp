#pragma once
// What the process's HDF5 library has been through, for the program's exit.

namespace oobleck::io {

/// Whether closing an HDF5 file failed in this process (its last writes failed: disk full, a
/// file-size limit). HDF5 1.10 keeps such a file half-closed and crashes when it shuts down at
/// exit (in H5_term_library); a program that sees this ends with std::_Exit once its own outputs
/// are closed (apps/main.cpp). The file itself was a temporary one and is removed.
bool hdf5_file_close_failed();

}  // namespace oobleck::io
