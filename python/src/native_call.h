#pragma once
// The C++ stretches of the Python module's calls, and the interpreter's exit (docs/python.md,
// "Threads and the GIL").
//
// A daemon thread still inside a call when the interpreter exits is stopped by Python as soon as it
// asks for the GIL again: PyEval_RestoreThread ends the thread with pthread_exit, which unwinds its
// stack. Two things cannot be unwound that way: a destructor that is noexcept (pybind11's
// gil_scoped_release re-acquires the GIL in one) and a joinable std::thread; either is
// std::terminate, "terminate called without an active exception", exit 134. And C++ still running
// while the process exits would race with the libraries' static destructors. So:
//   - WithoutGil releases the GIL for a stretch of C++, counted as a call in flight; its destructor
//     may unwind (noexcept(false)).
//   - RenderWorker joins the render's thread whatever way the caller leaves, cancelling it first,
//     and never touches Python; the thread counts as a call in flight while it runs.
//   - register_exit_hook() registers, with Python's atexit (run before the interpreter stops any
//     thread), a hook that cancels the renders in flight and waits until no call is inside its C++
//     stretch. After it a daemon thread that calls in (or whose render it cancelled) waits without
//     the GIL for the process to end, silently, as Python stops such threads at their next step
//     anyway; another thread gets RuntimeError ("the Python interpreter is exiting").
#include <Python.h>

#include <atomic>
#include <exception>
#include <functional>
#include <optional>
#include <thread>

namespace prizma::python {

// One call inside its C++ stretch (the exit hook waits for none to be); `cancel`, when given, is a
// render's cancellation flag, set by the exit hook. Constructed with the GIL held: once the hook
// has run, stop_if_exiting().
class CallInFlight {
 public:
  explicit CallInFlight(std::atomic<bool>* cancel = nullptr);
  ~CallInFlight();
  CallInFlight(const CallInFlight&) = delete;
  CallInFlight& operator=(const CallInFlight&) = delete;

 private:
  std::atomic<bool>* m_cancel;
};

// The GIL released until the end of the scope.
class GilReleased {
 public:
  GilReleased() : m_state(PyEval_SaveThread()) {}
  // Re-acquiring may end the thread (a daemon thread at exit): the unwinding must pass through.
  ~GilReleased() noexcept(false);
  GilReleased(const GilReleased&) = delete;
  GilReleased& operator=(const GilReleased&) = delete;

 private:
  PyThreadState* m_state;
  int m_uncaught = std::uncaught_exceptions();
};

// A stretch of C++ without the GIL: counted (CallInFlight), then the GIL released; at the end the
// GIL is taken back first.
class WithoutGil {
 public:
  explicit WithoutGil(std::atomic<bool>* cancel = nullptr) : m_call(cancel) {}

 private:
  CallInFlight m_call;
  GilReleased m_released;
};

// The render's worker thread, running `body` (which must not throw) as a call in flight whose
// `cancel` flag the exit hook sets; it stops counting when body returns (not when joined: the
// caller may be held in Python by a progress callback). Joined by the destructor, after setting
// `cancel` (the renderer stops within one sample per thread), when the caller leaves without
// join(). Never touches Python.
class RenderWorker {
 public:
  RenderWorker(std::atomic<bool>& cancel, std::function<void()> body);
  ~RenderWorker();
  RenderWorker(const RenderWorker&) = delete;
  RenderWorker& operator=(const RenderWorker&) = delete;
  void join() { m_thread.join(); }

 private:
  std::atomic<bool>& m_cancel;
  std::optional<CallInFlight> m_call;
  std::thread m_thread;
};

// Registers the exit hook above (once, at import). The GIL must be held.
void register_exit_hook();

// True once the exit hook has run.
bool interpreter_exiting();

// Once the exit hook has run (GIL held): a daemon thread waits for the process to end, never
// returning; any other thread gets spectral::RuntimeError. Before, nothing.
void stop_if_exiting();

}  // namespace prizma::python
