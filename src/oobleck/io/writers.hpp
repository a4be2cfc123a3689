#pragma once
// Who writes an output file (frames, checkpoints).

namespace oobleck::io {

/// `one`: this process writes the whole file with serial HDF5 calls. `every_rank`: the ranks of a
/// decomposed run (comm::size() > 1) write it together with parallel HDF5, each its own points
/// (concatenated in rank order) or its own block of the grid; rank 0 alone handles the folder, the
/// renaming and the index. With one rank, `every_rank` is `one`.
enum class Writers { one, every_rank };

}  // namespace oobleck::io
