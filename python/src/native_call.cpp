// The Python module's calls and the interpreter's exit (native_call.h).
#include "native_call.h"

#include <pybind11/pybind11.h>
#include <unistd.h>

#include <condition_variable>
#include <exception>
#include <mutex>
#include <set>

#include "prizma/spectral/error.h"

namespace prizma::python {
namespace {

struct ExitState {
  std::mutex mutex;
  std::condition_variable idle;
  int calls_in_flight = 0;
  bool exiting = false;
  std::set<std::atomic<bool>*> renders;  // cancellation flags of the renders running
};

// Never destroyed: a daemon thread may still use it while the process exits.
ExitState& exit_state() {
  static ExitState* state = new ExitState;
  return *state;
}

bool interpreter_finalizing() {
#if PY_VERSION_HEX >= 0x030D0000
  return Py_IsFinalizing() != 0;
#else
  return _Py_IsFinalizing() != 0;
#endif
}

// Python's atexit runs this on the main thread, before the interpreter stops any thread.
void cancel_and_wait_for_calls() {
  ExitState& s = exit_state();
  {
    const std::lock_guard lock(s.mutex);
    s.exiting = true;
    for (std::atomic<bool>* cancel : s.renders) cancel->store(true);
  }
  const GilReleased released;  // the calls in flight may need it to finish (a render relays progress)
  std::unique_lock lock(s.mutex);
  s.idle.wait(lock, [&] { return s.calls_in_flight == 0; });
}

}  // namespace

void stop_if_exiting() {
  if (!interpreter_exiting()) return;
  bool daemon = false;
  try {
    daemon = pybind11::module_::import("threading").attr("current_thread")().attr("daemon").cast<bool>();
  } catch (const std::exception&) {
    PyErr_Clear();
  }
  if (daemon) {
    (void)PyEval_SaveThread();
    for (;;) ::pause();
  }
  throw spectral::RuntimeError("the Python interpreter is exiting: no new prizma call is started");
}

CallInFlight::CallInFlight(std::atomic<bool>* cancel) : m_cancel(cancel) {
  stop_if_exiting();
  ExitState& s = exit_state();
  const std::lock_guard lock(s.mutex);
  ++s.calls_in_flight;
  if (m_cancel != nullptr) s.renders.insert(m_cancel);
}

CallInFlight::~CallInFlight() {
  ExitState& s = exit_state();
  const std::lock_guard lock(s.mutex);
  if (m_cancel != nullptr) s.renders.erase(m_cancel);
  if (--s.calls_in_flight == 0) s.idle.notify_all();
}

GilReleased::~GilReleased() noexcept(false) {
  // While another exception unwinds, a second (the thread's end) would be std::terminate: a thread
  // here while the interpreter finalizes waits for the process to exit instead, as Python 3.14's own
  // daemon threads do.
  if (std::uncaught_exceptions() > m_uncaught && interpreter_finalizing()) {
    for (;;) ::pause();
  }
  PyEval_RestoreThread(m_state);
}

RenderWorker::RenderWorker(std::atomic<bool>& cancel, std::function<void()> body)
    : m_cancel(cancel), m_call(std::in_place, &cancel), m_thread([this, body = std::move(body)] {
        body();
        m_call.reset();
      }) {}

RenderWorker::~RenderWorker() {
  if (!m_thread.joinable()) return;
  m_cancel.store(true);
  m_thread.join();
}

void register_exit_hook() {
  pybind11::module_::import("atexit").attr("register")(pybind11::cpp_function(&cancel_and_wait_for_calls));
}

bool interpreter_exiting() {
  ExitState& s = exit_state();
  const std::lock_guard lock(s.mutex);
  return s.exiting;
}

}  // namespace prizma::python
