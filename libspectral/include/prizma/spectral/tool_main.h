#pragma once
// The shared shape of every executable's main(): maps exceptions to one stderr line and an exit code.
//   InputError / CLI11 parse errors → "prog: error: <input>: <reason>", exit 2
//   other std::exception             → "prog: error: <what>", exit 1
#include <exception>
#include <functional>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "prizma/spectral/error.h"

namespace prizma::spectral {

constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;

// Runs body() and maps what it throws. body returns the exit code. Then flushes standard output:
// a write error there (a full disk, /dev/full) turns exit 0 into 1 with
// "prog: error: standard output: cannot write: <reason>". SIGXFSZ is ignored, so a file-size limit
// fails the write (exit 1) instead of killing the tool. While body() runs, the files it reads are
// recorded (InputRecording, input_file.h): no output of the run may replace one.
int run_tool(const std::string& program, const std::function<int()>& body);

// The standard output check of run_tool on its own (for --help / --version): returns `rc`, or
// kExitRuntime with the error line when rc is kExitOk and standard output could not be written.
int check_standard_output(const std::string& program, int rc);

// Version string "0.1.0 (git abc1234)" for --version and the files' prizma:version.
std::string prizma_version();

// True for a std::system_error that means the system ran out of memory or threads (a thread that
// cannot be started: EAGAIN, ENOMEM).
bool is_out_of_resources(const std::system_error& e);
// True for every way running out of memory shows: std::bad_alloc, the system_errors above, and
// TBB's "pthread_create has failed" (a std::runtime_error when it cannot start a worker).
bool is_out_of_memory(const std::exception& e);
// True when a library's error message (OpenEXR's Iex, OCIO) says that memory or threads ran out:
// "Out of memory", "std::bad_alloc", "Cannot allocate memory", "Resource temporarily unavailable".
// Text in double quotes is ignored: those messages quote file names and channel names, which come
// from the input and may contain these very words (a channel named "Cannot allocate memory").
bool message_says_out_of_memory(std::string_view what);

// Runs f(); running out of memory inside it (std::bad_alloc, or a thread that cannot be started)
// becomes RuntimeError("out of memory <what>"), e.g. what = "reading the scene's volume".
template <typename F>
decltype(auto) allocating(std::string_view what, F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw RuntimeError("out of memory " + std::string(what));
  } catch (const std::exception& e) {
    if (is_out_of_memory(e)) throw RuntimeError("out of memory " + std::string(what) + " (" + e.what() + ")");
    throw;
  }
}

// What escapes every handler (a library's static initialisation before main, a destructor after
// it) becomes one line "<program>: error: ..." and exit 1 instead of "terminate called ...": called
// by the terminate handler that PRIZMA_TOOL_STARTUP_GUARD installs.
[[noreturn]] void report_uncaught_and_exit(const char* program) noexcept;

// Called from the executable's .preinit_array by PRIZMA_TOOL_STARTUP_GUARD: the terminate handler
// above, and until end_startup_guard() (run_tool and parse_command_line call it) a SIGSEGV/SIGBUS
// handler: OpenImageIO's own initialiser crashes when an allocation fails under a memory limit
// before main, which is reported as out of memory in one line, exit 1.
void begin_startup_guard(const char* program) noexcept;
void end_startup_guard() noexcept;

// The same guard around a library loaded after main (dlopen of the image module, whose
// OpenImageIO initialisers are those above): while it lives, a SIGSEGV/SIGBUS or an exception
// escaping an initialiser becomes one line "<program>: error: [out of memory: ]… while <what>",
// exit 1. Not thread-safe: one at a time (the loader holds its lock).
class LoadGuard {
 public:
  explicit LoadGuard(const std::string& what) noexcept;
  ~LoadGuard();
  LoadGuard(const LoadGuard&) = delete;
  LoadGuard& operator=(const LoadGuard&) = delete;

 private:
  bool m_installed = false;
};

}  // namespace prizma::spectral

// In an executable's main.cpp: installs the terminate handler from the executable's
// .preinit_array, which runs before any shared library's initialisers. Debian's OpenImageIO pulls
// in OpenVDB → log4cplus, whose initialiser starts threads before main; under a memory limit
// (ulimit -v) that throws std::system_error before main can catch anything.
#define PRIZMA_TOOL_STARTUP_GUARD(program)                                                              \
  namespace {                                                                                         \
  [[noreturn]] void prizma_terminate_handler() { ::prizma::spectral::report_uncaught_and_exit(program); } \
  void prizma_preinit(int, char**, char**) {                                                          \
    std::set_terminate(prizma_terminate_handler);                                                   \
    ::prizma::spectral::begin_startup_guard(program);                                               \
  }                                                                                                 \
  __attribute__((section(".preinit_array"), used)) void (*const prizma_preinit_entry)(int, char**, char**) = \
      prizma_preinit;                                                                                 \
  }                                                                                                   \
  static_assert(true, "")

namespace prizma::spectral {

}  // namespace prizma::spectral
