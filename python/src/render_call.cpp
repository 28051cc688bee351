// prizma._prizma.render (module_parts.h): render() on a worker thread with the GIL released; the
// calling thread relays progress to the Python callback and checks for signals (Ctrl-C) every 50 ms,
// setting the renderer's cancellation flag when one arrives. render() then returns the passes
// completed so far. Integer arguments are checked as the tools check their options.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // Scene::warnings → a list of str

#include <atomic>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "module_parts.h"
#include "native_call.h"
#include "prizma/render/render.h"
#include "prizma/render/render_job.h"
#include "prizma/render/resume.h"
#include "prizma/render/sample_range.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"

namespace prizma::python {
namespace {

using spectral::InputError;

struct PythonError {  // a fetched Python exception (owned references), restored on the calling thread
  PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
  bool set() const { return type != nullptr; }
  void fetch() { PyErr_Fetch(&type, &value, &traceback); }
  void restore() {
    PyErr_Restore(type, value, traceback);
    type = value = traceback = nullptr;
  }
};

// An integer argument in [lo, hi] that no scene field matches (threads, samples_per_pass).
std::int64_t integer_in(const py::handle& value, const std::string& name, std::int64_t lo, std::int64_t hi,
                        const std::string& meaning) {
  const std::string text = integer_text(value, name);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < lo || v > hi)
    throw InputError(name, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" + meaning + " (got " +
                               text + ")");
  return v;
}

// What render() overrides of the scene, from its Python arguments (None: the scene's value).
struct RenderArguments {
  std::optional<std::int64_t> samples;
  render::RenderOverrides given;
  int threads = 0;
  std::int64_t samples_per_pass = 0;
};

RenderArguments render_arguments(const py::object& samples, const py::object& threads, const py::object& seed,
                                 const py::object& width, const py::object& height,
                                 const std::optional<std::string>& bins, bool variance,
                                 const py::object& samples_per_pass) {
  RenderArguments a;
  if (!samples.is_none()) a.samples = render::scene_integer_override(integer_text(samples, "samples"), "samples", "samples");
  if (!width.is_none())
    a.given.width = static_cast<int>(render::scene_integer_override(integer_text(width, "width"), "camera.width", "width"));
  if (!height.is_none())
    a.given.height =
        static_cast<int>(render::scene_integer_override(integer_text(height, "height"), "camera.height", "height"));
  if (!seed.is_none()) a.given.seed = render::scene_seed_override(integer_text(seed, "seed"), "seed");
  a.given.bins = bins;
  a.given.variance = variance;
  a.threads = static_cast<int>(integer_in(threads, "threads", 0, 65536, " (0: all cores)"));
  a.samples_per_pass = integer_in(samples_per_pass, "samples_per_pass", 0, std::int64_t{1} << 40, " (0: automatic)");
  return a;
}

}  // namespace

// long on purpose: the render thread and its progress relay to Python share the lock, the queue and the pending Python error.
py::dict render_scene(const std::string& scene_source, bool scene_is_json, const std::string& base_dir,
                      const py::object& samples, const py::object& threads, const py::object& seed,
                      const py::object& width, const py::object& height, const std::optional<std::string>& bins,
                      bool variance, const py::object& samples_per_pass, const py::object& progress) {
  const RenderArguments args = render_arguments(samples, threads, seed, width, height, bins, variance, samples_per_pass);
  render::Scene scene;
  {
    const WithoutGil released;
    scene = scene_is_json ? render::load_scene_text(scene_source, "scene", base_dir) : render::load_scene(scene_source);
  }
  const render::RenderOverrides given = render::prepare_render(scene, {args.given, args.samples, args.threads, ""});

  std::atomic<bool> cancel{false};
  std::mutex mutex;
  std::condition_variable wake;
  bool done = false;
  std::vector<render::RenderProgress> reports;  // not yet relayed, in order
  std::exception_ptr failure;
  spectral::SpectralImage image;
  render::RenderStats stats;
  render::RenderCallbacks cb;
  cb.cancel = &cancel;
  cb.samples_per_pass = args.samples_per_pass;
  cb.progress = [&](const render::RenderProgress& p) {
    const std::lock_guard lock(mutex);
    reports.push_back(p);
    wake.notify_all();
  };

  PythonError pending;
  bool interrupted_by_signal = false;
  {
    // Joined however this scope is left; a daemon thread stopped at the interpreter's exit included
    // (GilReleased below then unwinds through it: native_call.h).
    RenderWorker worker(cancel, [&] {
      try {
        image = render::render(scene, cb, &stats);
      } catch (...) {
        failure = std::current_exception();
      }
      const std::lock_guard lock(mutex);
      done = true;
      wake.notify_all();
    });
    for (bool finished = false; !finished;) {
      std::vector<render::RenderProgress> batch;
      {
        const GilReleased released;
        std::unique_lock lock(mutex);
        wake.wait_for(lock, std::chrono::milliseconds(50), [&] { return done || !reports.empty(); });
        batch.swap(reports);
        finished = done;
      }
      if (pending.set()) continue;  // cancelled: wait for the worker, call nothing more
      for (const render::RenderProgress& report : batch) {
        if (progress.is_none() || pending.set()) break;
        py::dict d;
        d["samples_done"] = report.samples_done;
        d["samples_total"] = report.samples_total;
        d["paths"] = report.paths;
        d["elapsed_seconds"] = report.elapsed_seconds;
        PyObject* r = PyObject_CallOneArg(progress.ptr(), d.ptr());
        if (r == nullptr) {
          pending.fetch();
          cancel.store(true);
        } else {
          Py_DECREF(r);
        }
      }
      if (pending.set()) continue;
      if (PyErr_CheckSignals() != 0) {
        pending.fetch();
        interrupted_by_signal = true;
        cancel.store(true);
      }
    }
    const GilReleased released;
    worker.join();
  }
  if (failure && !pending.set()) std::rethrow_exception(failure);
  if (pending.set()) {
    // Ctrl-C: the exception carries the passes completed so far (a valid, shorter render).
    interrupted_by_signal = interrupted_by_signal || PyErr_GivenExceptionMatches(pending.type, PyExc_KeyboardInterrupt);
    if (interrupted_by_signal && !failure && image.width > 0) {
      PyErr_NormalizeException(&pending.type, &pending.value, &pending.traceback);
      image.info.render_options = render::overrides_to_json(given);
      py::dict partial = image_to_py(std::move(image));
      if (pending.value != nullptr) PyObject_SetAttrString(pending.value, "_prizma_image", partial.ptr());
    }
    pending.restore();
    throw py::error_already_set();
  }
  if (stats.interrupted) stop_if_exiting();  // the exit hook cancelled it
  render::record_render(image, scene, given, !scene_is_json);
  py::dict out = image_to_py(std::move(image));
  py::dict s;
  s["paths"] = stats.paths;
  s["paths_in_volume"] = stats.paths_in_volume;
  s["collisions"] = stats.collisions;
  s["nan_or_inf_count"] = stats.nan_or_inf_count;
  s["samples_completed"] = stats.samples_completed;
  s["interrupted"] = stats.interrupted;
  s["wall_seconds"] = stats.wall_seconds;
  py::list warnings;  // what a library noticed in an input it still read (an OpenVDB file)
  for (const std::string& w : scene.warnings) warnings.append(w);
  s["warnings"] = warnings;
  out["stats"] = s;
  return out;
}

}  // namespace prizma::python
