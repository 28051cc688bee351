#pragma once
// One error line instead of a crash while shared libraries start up: the terminate handler and the
// SIGSEGV/SIGBUS guard an executable installs before main (PRIZMA_TOOL_STARTUP_GUARD,
// prizma/tool/tool_main.h), and the same guard around a module loaded after main (LoadGuard,
// module_loader.cpp). Here, not in prizma::tool, because the library's module loader uses it.
#include <string>

namespace prizma::spectral {

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
