#pragma once
// The shared shape of every executable's main(): maps exceptions to one stderr line and an exit code.
//   InputError / CLI11 parse errors → "prog: error: <input>: <reason>", exit 2
//   other std::exception             → "prog: error: <what>", exit 1
// prizma::tool is the executables' plumbing (this, cli_support.h); the libraries do not link it.
#include <exception>
#include <functional>
#include <string>

#include "prizma/spectral/error.h"
#include "prizma/spectral/out_of_memory.h"
#include "prizma/spectral/startup_guard.h"
#include "prizma/spectral/version.h"

namespace prizma::tool {

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

}  // namespace prizma::tool

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

