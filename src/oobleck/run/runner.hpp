#pragma once
// `oobleck run`: a scene file becomes a two-phase MPM run with HDF5/XDMF frames, a CSV series of
// global quantities, checkpoints and summary.json (issue 4, items 7–8).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oobleck/scene/config.hpp"

namespace oobleck::run {

struct RunOptions {
  std::string out_dir;  ///< run folder (created)
  int threads = 0;      ///< OpenMP threads (0: default)
  /// Decomposed runs (several MPI ranks): ranks per grid axis, "2x1" or "2x1x1" (empty: chosen,
  /// mpm/decomposition.hpp).
  std::string ranks_grid;
  long checkpoint_every = -1;  ///< steps between checkpoints (-1: the scene's value)
  bool quiet = false;          ///< no progress output
  bool restart = false;        ///< continue from out_dir/checkpoint.h5
  /// On a restart: the `--set` overrides of [time] the run continues with (a new time step or
  /// duration, e.g. a smaller time.cfl after a numerical failure). Non-empty: the checkpoint's
  /// time step may differ, the remaining steps are counted from the checkpoint's time, the
  /// outputs' step intervals from the checkpoint's step, and the run folder's scene.toml is
  /// replaced by the new one.
  std::vector<std::string> restart_overrides;
  long stop_after_steps = -1;  ///< stop (with a checkpoint) after this many steps in total (tests)
  /// Called after every step with (steps done, total steps, simulated time [s]); returning false
  /// stops the run there with a checkpoint, as stop_after_steps does, and summary.json says
  /// "stopped_by": "caller" (the Python module: Ctrl-C). Signals: run/stop.hpp.
  std::function<bool(long, long, double)> on_step;
};

/// Run the scene to its end and return the summary (also written to out_dir/summary.json).
nlohmann::json run_scene(const scene::SceneConfig& config, const RunOptions& options);

/// The scene a `--restart` of `run_dir` continues: the folder's stored scene with `overrides`,
/// which may only set [time] keys (InputError naming any other key, or a folder without a
/// checkpoint); sets `options`' out_dir, restart and restart_overrides.
scene::SceneConfig restart_scene(const std::string& run_dir, const std::vector<std::string>& overrides,
                                 RunOptions& options);

/// Path of the checkpoint file in a run folder.
std::string checkpoint_path(const std::string& run_dir);
/// Path of the resolved scene stored in a run folder (used by --restart).
std::string stored_scene_path(const std::string& run_dir);

}  // namespace oobleck::run
