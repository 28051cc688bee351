// The library side of the tools' process plumbing: the version, what running out of memory looks
// like, and the start-up guard (out_of_memory.h, startup_guard.h, version.h).
#include "prizma/spectral/out_of_memory.h"
#include "prizma/spectral/startup_guard.h"
#include "prizma/spectral/version.h"

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string_view>
#include <system_error>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/stderr_capture.h"

#ifndef PRIZMA_VERSION
#define PRIZMA_VERSION "0.0.0"
#endif
namespace prizma::spectral {

namespace detail {
// Generated at build time by cmake/PrizmaRevision.cmake ("" when unknown).
const char* git_revision();
}  // namespace detail

std::string prizma_version() {
  std::string v = PRIZMA_VERSION;
  const std::string rev = detail::git_revision();
  if (!rev.empty()) v += " (git " + rev + ")";
  return v;
}

bool is_out_of_resources(const std::system_error& e) {
  return e.code() == std::errc::resource_unavailable_try_again || e.code() == std::errc::not_enough_memory;
}

bool is_out_of_memory(const std::exception& e) {
  if (dynamic_cast<const RuntimeError*>(&e) != nullptr) return false;  // already says what it is
  if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr) return true;
  if (const auto* s = dynamic_cast<const std::system_error*>(&e)) return is_out_of_resources(*s);
  return std::string_view(e.what()).find("pthread_create has failed") != std::string_view::npos;
}

bool message_says_out_of_memory(std::string_view what) {
  // Only the text before the first quote and after the last: names from a file (its path, its
  // channels) are quoted and may hold quotes themselves (a channel `a"Out of memory`), so pairing
  // the quotes one by one can put a file's text outside them. Nothing after a lone quote.
  const std::size_t first = what.find('"'), last = what.rfind('"');
  std::string unquoted(what.substr(0, first));
  if (first != std::string_view::npos && last != first) unquoted += what.substr(last + 1);
  for (const std::string_view marker :
       {"ut of memory", "bad_alloc", "Cannot allocate memory", "Resource temporarily unavailable"}) {
    if (unquoted.find(marker) != std::string::npos) return true;
  }
  return false;
}

namespace {
// What LoadGuard is loading ("" when nothing): for the messages of a crash or an exception in a
// library's initialiser. A fixed buffer: read by a signal handler.
char g_load_what[256] = {};
}  // namespace

void report_uncaught_and_exit(const char* program) noexcept {
  // stdio only and no allocation: this may run before the C++ library's own initialisation
  // (iostreams), and memory may be exhausted. A StderrCapture may hold stderr: the line goes to
  // the real one.
  if (detail::g_captured_stderr >= 0) ::dup2(detail::g_captured_stderr, STDERR_FILENO);
  const char* reason = "unknown failure";
  const char* detail = "";
  try {
    if (const std::exception_ptr e = std::current_exception()) std::rethrow_exception(e);
    // A library that calls std::terminate itself (log4cplus's initialiser when it cannot start its
    // thread, loaded with OpenImageIO) leaves no exception: under an address-space limit that is
    // running out of memory.
    rlimit lim{};
    const bool limited = ::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY;
    reason = !limited                 ? "terminated (no exception)"
             : g_load_what[0] != '\0' ? "out of memory: a library stopped the program while "
                                       : "out of memory: a library stopped the program while starting up";
    if (limited && g_load_what[0] != '\0') detail = g_load_what;
  } catch (const std::bad_alloc&) {
    reason = "out of memory (while a library started up or shut down, outside Prizma's code)";
  } catch (const std::system_error& e) {
    reason = !is_out_of_resources(e) ? ""
             : g_load_what[0] != '\0' ? "out of memory: a library cannot start its threads: "
                                       : "out of memory: a library cannot start its threads before main: ";
    detail = e.what();
  } catch (const std::exception& e) {
    reason = "";
    detail = e.what();
  } catch (...) {
  }
  std::fprintf(stderr, "%s: error: %s%s\n", program, reason, detail);
  std::fflush(stderr);
  std::_Exit(1);  // kExitRuntime (prizma/tool/tool_main.h)
}

namespace {
const char* g_startup_program = nullptr;
struct sigaction g_old_segv {};
struct sigaction g_old_bus {};
bool g_guard_active = false;
stack_t g_old_altstack{};
bool g_altstack_set = false;

extern "C" void on_startup_crash(int) {
  // Async-signal-safe only: write(2) and _exit.
  static const char kMsg[] =
      ": error: out of memory: a library crashed while starting up, before main (its allocation failed under the "
      "address-space limit)\n";
  static const char kOther[] = ": error: a library crashed while starting up, before main (SIGSEGV)\n";
  static const char kLoadMsg[] = ": error: out of memory: a library crashed while ";
  static const char kLoadTail[] = " (its allocation failed under the address-space limit)\n";
  static const char kLoadOther[] = ": error: a library crashed (SIGSEGV) while ";
  rlimit lim{};
  const bool limited = ::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY;
  const char* p = g_startup_program != nullptr ? g_startup_program : "prizma";
  if (detail::g_captured_stderr >= 0) ::dup2(detail::g_captured_stderr, STDERR_FILENO);
  const auto put = [](const char* s) {
    std::size_t n = 0;
    while (s[n] != '\0') ++n;
    [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, s, n);
  };
  put(p);
  if (g_load_what[0] != '\0') {
    put(limited ? kLoadMsg : kLoadOther);
    put(g_load_what);
    put(limited ? kLoadTail : "\n");
  } else {
    put(limited ? kMsg : kOther);
  }
  ::_exit(1);  // kExitRuntime
}
}  // namespace

void begin_startup_guard(const char* program) noexcept {
  g_startup_program = program;
  // On its own stack: the crash may be the main stack failing to grow under the limit.
  alignas(16) static char alt_stack[1 << 16];
  stack_t ss{};
  ss.ss_sp = alt_stack;
  ss.ss_size = sizeof alt_stack;
  g_altstack_set = ::sigaltstack(&ss, &g_old_altstack) == 0;
  struct sigaction sa {};
  sa.sa_handler = on_startup_crash;
  sa.sa_flags = SA_ONSTACK;
  sigemptyset(&sa.sa_mask);
  g_guard_active = ::sigaction(SIGSEGV, &sa, &g_old_segv) == 0 && ::sigaction(SIGBUS, &sa, &g_old_bus) == 0;
}

void end_startup_guard() noexcept {
  if (!g_guard_active) return;
  ::sigaction(SIGSEGV, &g_old_segv, nullptr);
  ::sigaction(SIGBUS, &g_old_bus, nullptr);
  if (g_altstack_set) ::sigaltstack(&g_old_altstack, nullptr);  // the sanitizers' own, if any
  g_guard_active = false;
}

LoadGuard::LoadGuard(const std::string& what) noexcept {
  const std::size_t n = std::min(what.size(), sizeof g_load_what - 1);
  std::memcpy(g_load_what, what.data(), n);
  g_load_what[n] = '\0';
  m_installed = !g_guard_active;
  if (m_installed) begin_startup_guard(g_startup_program != nullptr ? g_startup_program : "prizma");
}

LoadGuard::~LoadGuard() {
  if (m_installed) end_startup_guard();
  g_load_what[0] = '\0';
}

}  // namespace prizma::spectral
