// `oobleck run SCENE.toml`: a two-phase MPM run from a scene file (docs/scenes.md), and
// `oobleck run --restart DIR` to continue from the run's last checkpoint.

#include <fmt/format.h>

#include "cli_common.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/run/stop.hpp"
#include "oobleck/scene/config.hpp"
#include "oobleck/scene/key_list.hpp"

namespace oobleck::cli {

void add_run_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("run", "run a scene file (two-phase MPM): HDF5/XDMF frames, series.csv, summary.json");
  struct Opts {
    std::string scene, out, restart, ranks_grid;
    std::vector<std::string> sets;
    int threads = 0;
    long checkpoint_every = -1;
    long stop_after = -1;
    bool quiet = false;
    bool list_keys = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "scene file (TOML)");
  cmd->add_option("--out", o->out, "run folder (default: out/<scene name>)");
  cmd->add_option("--set", o->sets,
                  "override a scene key: key.path=value or a short name from [aliases] (with --restart: [time] "
                  "keys only)");
  cmd->add_option("--threads", o->threads, "OpenMP threads; 0 (the default) means all cores");
  cmd->add_option("--ranks-grid", o->ranks_grid,
                  "under mpirun: ranks per grid axis, e.g. 2x1 or 2x1x1 (default: the split with the fewest ghost "
                  "nodes)");
  cmd->add_option("--checkpoint-every", o->checkpoint_every, "steps between checkpoints (default: the scene's)");
  cmd->add_option("--restart", o->restart, "continue the run in this folder from its last checkpoint");
  cmd->add_option("--stop-after", o->stop_after, "stop after this many steps in total (leaves a checkpoint)");
  cmd->add_flag("--quiet", o->quiet, "no progress output");
  cmd->add_flag("--list-keys", o->list_keys,
                "print the scene's short names and keys with their values, units and meanings, and exit");
  cmd->callback([o] {
    if (o->threads < 0) throw InputError(fmt::format("--threads = {}: must be >= 0", o->threads));
    if (o->list_keys) {
      if (o->scene.empty()) throw InputError("run --list-keys: a scene file is required");
      fmt::print("{}", scene::format_scene_keys(scene::list_scene_keys(o->scene)));
      return;
    }
    run::RunOptions ro;
    ro.threads = o->threads;
    ro.ranks_grid = o->ranks_grid;
    ro.checkpoint_every = o->checkpoint_every;
    ro.quiet = o->quiet;
    ro.stop_after_steps = o->stop_after;
    scene::SceneConfig cfg;
    if (!o->restart.empty()) {
      if (!o->scene.empty()) throw InputError("--restart DIR continues the stored scene of DIR: give no scene file");
      cfg = run::restart_scene(o->restart, o->sets, ro);
    } else {
      if (o->scene.empty()) throw InputError("run: a scene file is required (or --restart DIR)");
      cfg = scene::load_scene(o->scene, o->sets);  // validates everything before any output
      ro.out_dir = o->out.empty() ? "out/" + cfg.name : o->out;
      // The run folder and its parents are created by the run once the scene and the solver have
      // been set up (out/ in a fresh checkout), so a refused scene leaves nothing behind.
    }
    const run::StopOnSignals stop_on_signals;  // Ctrl-C: checkpoint, summary, exit 130 (main.cpp)
    const auto summary = run::run_scene(cfg, ro);
    if (!comm::is_root()) return;
    fmt::print(
        "{}: {} points x {} steps in {:.3g} s = {:.3g} point updates/s on {} rank(s) x {} thread(s); output in {}\n",
        cfg.name, summary["points"].get<long>(), summary["steps_this_run"].get<long>(),
        summary["wall_seconds"].get<double>(), summary["point_updates_per_second"].get<double>(),
        summary["ranks"].get<int>(), summary["threads"].get<int>(), ro.out_dir);
  });
}

}  // namespace oobleck::cli
