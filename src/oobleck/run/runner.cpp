#include "oobleck/run/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/decomposition.hpp"
#include "oobleck/io/frames.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/io/progress.hpp"
#include "oobleck/io/run_lock.hpp"
#include "oobleck/io/series.hpp"
#include "oobleck/io/summary.hpp"
#include "oobleck/run/analysis.hpp"
#include "oobleck/run/finite_check.hpp"
#include "oobleck/run/run_output.hpp"
#include "oobleck/run/run_summary.hpp"
#include "oobleck/run/snapshots.hpp"
#include "oobleck/run/stop.hpp"
#include "oobleck/run/units.hpp"
#include "oobleck/run/checkpoint_state.hpp"
#include "oobleck/scene/build.hpp"
#include "oobleck/scene/third_bodies.hpp"

namespace oobleck::run {

std::string checkpoint_path(const std::string& run_dir) { return run_dir + "/checkpoint.h5"; }
std::string stored_scene_path(const std::string& run_dir) { return run_dir + "/scene.toml"; }

scene::SceneConfig restart_scene(const std::string& run_dir, const std::vector<std::string>& overrides,
                                 RunOptions& options) {
  if (!std::filesystem::exists(checkpoint_path(run_dir)))
    throw InputError(
        fmt::format("restart {}: no checkpoint there ({} is missing); a run writes one every "
                    "--checkpoint-every N steps (Python: checkpoint_every=N)",
                    run_dir, checkpoint_path(run_dir)));
  scene::SceneConfig cfg = scene::load_scene(stored_scene_path(run_dir), overrides);
  for (const auto& spec : overrides) {  // the rest of the scene is the checkpoint's state
    const std::string key = scene::override_key(spec, cfg.aliases);
    if (key.rfind("time.", 0) != 0)
      throw InputError(
          fmt::format("restart {} with --set {}: only [time] keys (time.cfl, time.dt, time.duration) "
                      "may change on a restart; '{}' is part of the checkpoint's state",
                      run_dir, spec, key));
  }
  options.out_dir = run_dir;
  options.restart = true;
  options.restart_overrides = overrides;
  return cfg;
}

namespace {

using scene::SceneConfig;
namespace fs = std::filesystem;

/// One run of a scene: the solver built from the configuration (scene/build.hpp), its analysis
/// (analysis.hpp), the snapshots, and the loop that steps, samples and writes.
template <class G>
class SceneRun {
 public:
  SceneRun(const SceneConfig& cfg, const RunOptions& opt)
      : cfg_(cfg),
        opt_(opt),
        scene_(scene::build_scene<G>(cfg, opt.threads)),
        analysis_(make_analysis<G>(cfg, scene_)),
        snapshots_(cfg, scene_, opt.out_dir) {}

  nlohmann::json run();

 private:
  /// Steps between events every `interval_s` (fallback when the interval is 0).
  long steps_between(double interval_s, long fallback) const {
    return interval_s > 0 ? std::max(1L, static_cast<long>(std::llround(interval_s / scene_.dt_s))) : fallback;
  }
  void check_decomposable() const;
  mpm::Decomposition<G::dim> layout() const;
  void decompose();
  void make_run_folder();
  void start(std::optional<io::FrameWriter>& frames, std::optional<io::SeriesWriter>& series);
  void write_frame(io::FrameWriter& frames);
  void take_due_snapshots(bool final_step);
  void check_finite() const;
  /// Everything a restart needs (run/checkpoint_state.hpp): solver, snapshots, analysis.
  mpm::FieldList state_fields();
  void write_checkpoint();
  void restore(const io::Checkpoint& cp);

  mpm::Solver<G>& solver() const { return *scene_.solver; }
  /// Who writes the frames and checkpoints: every rank of a decomposed run together.
  io::Writers writers() const { return solver().decomposition() ? io::Writers::every_rank : io::Writers::one; }

  const SceneConfig& cfg_;
  RunOptions opt_;
  scene::BuiltScene<G> scene_;
  std::unique_ptr<SceneAnalysis<G>> analysis_;
  Snapshots<G> snapshots_;
  std::optional<io::RunFolderLock> lock_;  ///< held from before the first write to the end
};

/// A --ranks-grid that does not fit the ranks (docs/mpi.md) or the grid: InputError before any
/// output.
template <class G>
void SceneRun<G>::check_decomposable() const {
  const int ranks = comm::size();
  if (ranks == 1) {
    if (!opt_.ranks_grid.empty()) {
      const auto dims = mpm::parse_ranks_grid<G::dim>(opt_.ranks_grid, "--ranks-grid");
      int n = 1;
      for (int d : dims) n *= d;
      if (n != 1)
        throw InputError(fmt::format("--ranks-grid {}: {} ranks, but this run has 1 (start it with mpirun -np {})",
                                     opt_.ranks_grid, n, n));
    }
    return;
  }
  (void)layout();  // a --ranks-grid that does not fit the ranks or the grid: refused before any output
}

template <class G>
mpm::Decomposition<G::dim> SceneRun<G>::layout() const {
  std::array<int, G::dim> dims{};
  if (!opt_.ranks_grid.empty()) dims = mpm::parse_ranks_grid<G::dim>(opt_.ranks_grid, "--ranks-grid");
  // Points per cell layer along each axis, over every body (each rank holds the whole scene
  // here): the cuts balance the points, not the cells (a bed under empty space).
  constexpr int D = G::dim;
  const auto& grid = solver().grid();
  typename mpm::Decomposition<D>::Load load;
  for (int a = 0; a < D; ++a) load[a].assign(static_cast<std::size_t>(grid.cells[a]), 0.0);
  for (int b = 0; b < solver().body_count(); ++b)
    for (const auto& x : solver().body(b).x_m)
      for (int a = 0; a < D; ++a) {
        const double r = (grid.wrapped(a, x[a]) - grid.origin_m[a]) / grid.h_m;
        load[a][static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor(r)), 0, grid.cells[a] - 1))] += 1.0;
      }
  return mpm::Decomposition<D>(grid, comm::size(), comm::rank(), dims, load);
}

/// Several ranks: keep this rank's block of the scene that every rank built (or restored).
template <class G>
void SceneRun<G>::decompose() {
  if (comm::size() > 1) solver().decompose(layout());
}

template <class G>
void SceneRun<G>::make_run_folder() {
  if (!comm::is_root()) return;  // (rank 0 writes every file of a decomposed run)
  std::error_code ec;
  fs::create_directories(opt_.out_dir, ec);
  if (ec || !fs::is_directory(opt_.out_dir))
    throw InputError(fmt::format("--out {}: cannot create the run folder: {}", opt_.out_dir,
                                 ec ? ec.message() : "a file of that name is in the way"));
  lock_.emplace(opt_.out_dir);
}

/// Open the frames and the series: continued from the checkpoint on a restart (whose analysis
/// holds its samples), or new with the state at t = 0 written and sampled.
template <class G>
void SceneRun<G>::start(std::optional<io::FrameWriter>& frames, std::optional<io::SeriesWriter>& series) {
  const bool root = comm::is_root();
  if (opt_.restart) {
    // Every rank restores the whole checkpoint (any rank count wrote it), then keeps its block.
    const io::Checkpoint cp = io::read_checkpoint(checkpoint_path(opt_.out_dir));
    restore(cp);
    decompose();
    frames.emplace(io::FrameWriter::resume(opt_.out_dir, cp.step(), "frames", writers()));
    if (!root) return;
    // New [time] settings (RunOptions::restart_overrides): a later plain --restart keeps them.
    if (!opt_.restart_overrides.empty())
      io::write_file_atomically(stored_scene_path(opt_.out_dir), cfg_.resolved_toml, "scene copy");
    const Columns columns = series_columns(scene_);
    series.emplace(io::SeriesWriter::resume(opt_.out_dir + "/series.csv", columns.names, cp.time(), columns.units));
    return;
  }
  decompose();
  if (root) {
    io::write_file_atomically(stored_scene_path(opt_.out_dir), cfg_.resolved_toml, "scene copy");
    const Columns columns = series_columns(scene_);
    series.emplace(opt_.out_dir + "/series.csv", columns.names, columns.units);
  }
  frames.emplace(opt_.out_dir, "frames", writers());
  write_frame(*frames);
  const auto row = series_row(scene_);
  if (series) series->row(row);
  analysis_->sample();
  take_due_snapshots(false);
}

template <class G>
void SceneRun<G>::write_frame(io::FrameWriter& frames) {
  run::write_frame(frames, scene_);
  analysis_->at_frame();
}

template <class G>
void SceneRun<G>::take_due_snapshots(bool final_step) {
  while (snapshots_.due(final_step)) analysis_->at_snapshot(snapshots_.write_next());
}

template <class G>
void SceneRun<G>::check_finite() const {
  for (int b = 0; b < solver().body_count(); ++b) {
    const auto& body = solver().body(b);
    // The step's G2P and the body's law check what they write (x, v, V; the stress) as they write
    // it; scan the body only where one of them did not check or found a non-finite value.
    if (solver().first_non_finite_kinematics(b) == mpm::kAllFinite && body.law &&
        body.law->first_non_finite_stress() == mpm::kAllFinite)
      continue;
    if (const auto bad = first_non_finite(body)) {
      throw NumericalError(fmt::format(
          "non-finite {} at step {} (t = {:.6g} s): body '{}' (law: {}), point {}; stopping before any output "
          "of this step is written",
          bad->what, solver().steps(), solver().time_s(), body.name, body.law ? body.law->name() : "none", bad->point));
    }
  }
}

template <class G>
mpm::FieldList SceneRun<G>::state_fields() {
  mpm::FieldList list = solver_fields(scene_);
  snapshots_.declare_fields(list);
  analysis_->declare_fields(list);
  return list;
}

template <class G>
void SceneRun<G>::write_checkpoint() {
  io::CheckpointWriter cp(checkpoint_path(opt_.out_dir), writers());  // (decomposed: every rank)
  cp.set_step(solver().steps());
  cp.set_time(solver().time_s());
  cp.set_config(cfg_.resolved_toml);
  cp.attribute("dt", scene_.dt_s);
  cp.attribute("threads", static_cast<std::int64_t>(solver().threads()));
  save_fields(cp, state_fields(), [](const char* unit) { return in_measure<G>(unit); });
  cp.commit();
}

template <class G>
void SceneRun<G>::restore(const io::Checkpoint& cp) {
  if (cp.real_attribute("dt") != scene_.dt_s && opt_.restart_overrides.empty()) {
    throw InputError(
        fmt::format("{}: time step {} s differs from the checkpoint's {} s (a new time step is "
                    "given with --restart DIR --set time.cfl=... or time.dt=...)",
                    cp.file(), scene_.dt_s, cp.real_attribute("dt")));
  }
  restore_fields(cp, state_fields());
  solver().set_clock(cp.time(), cp.step());
}

template <class G>
nlohmann::json SceneRun<G>::run() {
  check_decomposable();
  make_run_folder();
  const long every_frame = steps_between(cfg_.output.frame_interval_s, std::numeric_limits<long>::max());
  const long every_series = steps_between(cfg_.output.series_interval_s, 100);
  const long every_cp = opt_.checkpoint_every >= 0 ? opt_.checkpoint_every : cfg_.output.checkpoint_every;
  const long every_sample = steps_between(
      cfg_.analysis.sample_interval_s > 0 ? cfg_.analysis.sample_interval_s : cfg_.time.duration_s / 200.0, 1);

  std::optional<io::FrameWriter> frames;
  std::optional<io::SeriesWriter> series;
  start(frames, series);
  const long first = static_cast<long>(solver().steps());
  // A restart with new [time] settings counts its remaining steps from the checkpoint's time, and
  // the outputs' step intervals from the checkpoint's step.
  const bool retimed = opt_.restart && !opt_.restart_overrides.empty();
  const long total =
      retimed
          ? first +
                std::max(0L, static_cast<long>(std::llround((cfg_.time.duration_s - solver().time_s()) / scene_.dt_s)))
          : scene_.total_steps;
  const long base = retimed ? first : 0;

  std::int64_t points = 0;
  for (int b = 0; b < solver().body_count(); ++b) points += solver().body(b).size();
  points = comm::sum(points);
  io::ProgressOptions po;
  po.quiet = opt_.quiet || !comm::is_root();
  po.points_per_step = static_cast<double>(points);
  po.label = cfg_.name;
  io::Progress progress(static_cast<std::uint64_t>(total), po);

  long last = opt_.stop_after_steps >= 0 ? std::min<long>(opt_.stop_after_steps, total) : total;
  solver().reset_timings();
  const auto t0 = std::chrono::steady_clock::now();
  std::string stopped_by;  // a caller's (on_step) or a signal's stop before the last step
  const bool decomposed = solver().decomposition() != nullptr;
  for (long s = first + 1; s <= last; ++s) {
    for (const auto& tb : scene_.third)  // prescribed bodies ramping up to speed
      if (tb.cfg->ramp_time_s > 0.0)
        solver().set_prescribed_velocity(tb.body,
                                         scene::prescribed_velocity<G::ncomp>(*tb.cfg, solver().time_s(), scene_.dt_s));
    solver().step();
    check_finite();  // before anything of this step is measured or written
    analysis_->after_step();
    const bool final_step = s == total;
    const long k = s - base;
    if (k % every_sample == 0 || final_step) analysis_->sample();
    take_due_snapshots(final_step);
    if (k % every_frame == 0 || final_step) write_frame(*frames);
    if (k % every_series == 0 || final_step) {
      const auto row = series_row(scene_);
      if (series) series->row(row);
    }
    if (every_cp > 0 && k % every_cp == 0) write_checkpoint();
    progress.update(static_cast<std::uint64_t>(s), solver().time_s());
    if (opt_.on_step && !opt_.on_step(s, total, solver().time_s())) {
      if (s < last) stopped_by = "caller";  // a checkpoint, as for stop_after_steps
      last = s;
      break;
    }
    // run/stop.hpp: after this step's output (decomposed: a signal to any rank stops them all)
    if ((decomposed ? comm::any(stop_requested()) : stop_requested()) && s < last) {
      stopped_by = stop_reason(stop_signal());
      last = s;
      break;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (last < total) write_checkpoint();  // stopped early: leave a checkpoint to continue from
  progress.finish();
  if (frames) frames->flush();

  nlohmann::json j = run_summary(cfg_, scene_, *analysis_, snapshots_, last - first, last == total, wall);
  if (!stopped_by.empty()) j["stopped_by"] = stopped_by;
  if (retimed) j["restart_overrides"] = opt_.restart_overrides;
  if (comm::is_root()) io::write_summary(opt_.out_dir, j);
  if (!stopped_by.empty() && stopped_by != "caller") {
    throw Stopped(fmt::format("{}: stopped by {} after step {} (t = {:.6g} s); the checkpoint is written: continue "
                              "with `oobleck run --restart {}`",
                              cfg_.name, stop_reason(stop_signal()), last, solver().time_s(), opt_.out_dir),
                  stop_signal());
  }
  return j;
}

}  // namespace

nlohmann::json run_scene(const SceneConfig& config, const RunOptions& options) {
  if (options.out_dir.empty()) throw InputError("run: empty output folder");
  switch (config.grid.geometry) {
    case scene::Geometry::PlaneStrain: return SceneRun<mpm::PlaneStrain>(config, options).run();
    case scene::Geometry::Axisymmetric: return SceneRun<mpm::Axisymmetric>(config, options).run();
    case scene::Geometry::ThreeD: return SceneRun<mpm::ThreeD>(config, options).run();
  }
  return {};
}

}  // namespace oobleck::run
