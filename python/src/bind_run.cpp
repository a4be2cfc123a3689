// oobleck._oobleck.run_scene: `oobleck run` without the GIL, with Ctrl-C and progress in Python.
#include <chrono>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bind.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::python {
namespace {

/// `oobleck run` without the GIL. Every 0.1 s (and at the end) the GIL is taken to deliver
/// signals (Ctrl-C: PyErr_CheckSignals raises KeyboardInterrupt, which stops the run after the
/// current step with a checkpoint) and to call `progress(done, total, time)`. Returns the summary
/// as JSON text and whether the run was interrupted; the pending Python exception, if any, is
/// raised by the caller (oobleck.run) after the run folder is complete.
py::tuple run_scene(const std::string& scene, const std::vector<std::string>& sets, const std::string& out, int threads,
                    long checkpoint_every, long stop_after, bool restart, py::object progress) {
  if (threads < 0) throw InputError(fmt::format("threads = {}: must be >= 0", threads));
  run::RunOptions ro;
  ro.threads = threads;
  ro.checkpoint_every = checkpoint_every;
  ro.quiet = true;  // progress is Python's (tqdm or text)
  ro.stop_after_steps = stop_after;
  scene::SceneConfig cfg;
  if (restart) {
    cfg = run::restart_scene(out, sets, ro);  // sets: [time] keys only
  } else {
    cfg = scene::load_scene(scene, sets);
    ro.out_dir = out.empty() ? "out/" + cfg.name : out;
  }
  bool interrupted = false;
  py::object error_type, error_value, error_trace;
  // With the GIL held: stop the run, keeping the pending Python exception for the caller.
  auto stop_with_pending_error = [&] {
    interrupted = true;
    PyObject *t = nullptr, *v = nullptr, *tb = nullptr;
    PyErr_Fetch(&t, &v, &tb);
    error_type = py::reinterpret_steal<py::object>(t);
    error_value = py::reinterpret_steal<py::object>(v);
    error_trace = py::reinterpret_steal<py::object>(tb);
    return false;
  };
  using clock = std::chrono::steady_clock;
  auto last = clock::now();
  ro.on_step = [&](long done, long total, double time) {
    const auto now = clock::now();
    if (done < total && now - last < std::chrono::milliseconds(100)) return true;
    last = now;
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) return stop_with_pending_error();
    if (!progress.is_none()) {
      try {
        progress(done, total, time);
      } catch (py::error_already_set& e) {
        e.restore();
        return stop_with_pending_error();
      }
    }
    return true;
  };
  nlohmann::json summary;
  {
    py::gil_scoped_release release;
    summary = run::run_scene(cfg, ro);
  }
  py::object err = py::none();
  if (interrupted && error_value)
    err = error_value;
  else if (interrupted && error_type)
    err = error_type();
  return py::make_tuple(summary.dump(), ro.out_dir, err);
}

}  // namespace

void bind_run(py::module_& m) {
  m.def("run_scene", &run_scene, py::arg("scene"), py::arg("sets"), py::arg("out"), py::arg("threads"),
        py::arg("checkpoint_every"), py::arg("stop_after"), py::arg("restart"), py::arg("progress"));
}

}  // namespace oobleck::python
